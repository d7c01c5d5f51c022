"""The monitor on a live ROS 1 system: a real master per test, real publishers in other processes."""
import json
import os
import signal
import subprocess
import time

import pytest

from conftest import ROOT
from rosharness import LIB, PY, TWIST, brake_after, first, listen_until_stopped, records, spec, wait_log

pytestmark = pytest.mark.ros

def test_violation_publishes_the_stop(ros, tmp_path):
    ros.monitor(spec(tmp_path, "entity base { rules: fast: topic /cmd_vel.linear.x > 1.0 m/s; }\n"
                               "if (base.fast) then { stop; }\n"))
    rec = ros.probe({"listen": [{"topic": "/safety_cmd", "type": TWIST}],
                     "advertise": [{"topic": "/cmd_vel", "type": TWIST}],
                     "steps": [{"wait_subscribers": "/cmd_vel"}, {"wait_publishers": "/safety_cmd"}, {"sleep": 0.3},
                               {"publish": "/cmd_vel", "msg": {"linear": {"x": 0.5}}}, {"sleep": 0.3},
                               {"publish": "/cmd_vel", "msg": {"linear": {"x": 2.0}}},
                               {"wait": "/safety_cmd", "timeout": 5}]})
    sent = [r for r in rec if r["kind"] == "sent"][-1]
    stop = first(rec, "recv", "/safety_cmd")
    assert stop is not None, rec
    assert stop["msg"] == {"linear": {"x": 0.0, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": 0.0}}
    assert 0 <= stop["wall"] - sent["wall"] < 0.1


def test_for_rule_fires_at_t0_plus_T(ros, tmp_path):
    ros.monitor(spec(tmp_path, "entity a { rules: r: (topic /x.data > 1) for 0.5 s; }\nif (a.r) then { stop; }\n"))
    rec = ros.probe({"listen": [{"topic": "/safety_cmd", "type": TWIST}],
                     "advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
                     "steps": [{"wait_subscribers": "/x"}, {"wait_publishers": "/safety_cmd"}, {"sleep": 0.3},
                               {"publish": "/x", "msg": {"data": 2.0}},  # one message, then silence
                               {"wait": "/safety_cmd", "timeout": 5}]})
    t0 = first(rec, "sent", "/x")["wall"]
    stop = first(rec, "recv", "/safety_cmd")
    assert stop is not None
    assert stop["wall"] - t0 == pytest.approx(0.5, abs=0.02)


def test_sigkill_of_a_watched_node_turns_alive_false(ros, tmp_path):
    victim = ros.probe_bg({"node": "victim", "anonymous": False, "steps": [{"sleep": 60}]}, name="victim")
    mon = ros.monitor(spec(tmp_path, "entity n: /victim { rules: dead: not alive(node /victim); }\n"
                                     "if (n.dead) then { stop; }\n"), node_rate=10)
    listener = listen_until_stopped(ros, "/safety_cmd", TWIST)
    time.sleep(0.5)
    assert victim.poll() is None and mon.poll() is None
    killed = time.time()
    os.kill(victim.pid, signal.SIGKILL)
    rec = records(listener)
    stop = first(rec, "recv", "/safety_cmd")
    assert stop is not None, ros.log(mon)
    assert stop["wall"] > killed  # not before: the victim was alive until then
    assert stop["wall"] - killed < 0.1 + 0.1 + 0.05  # one node sample + 100 ms (+ scheduling slack)


def test_publisher_silence_fires_an_age_rule(ros, tmp_path):
    ros.monitor(spec(tmp_path, "entity o { rules: silent: age(topic /odom) > 0.4 s; }\nif (o.silent) then { brake; }\n"))
    rec = ros.probe({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}],
                     "advertise": [{"topic": "/odom", "type": "std_msgs/Float64"}],
                     "steps": [{"wait_subscribers": "/odom"}, {"wait_publishers": "/brake"},
                               {"publish": "/odom", "msg": {"data": 1.0}, "repeat": 30, "period": 0.05},
                               {"mark": "silence"}, {"wait": "/brake", "timeout": 5, "fresh": True}]})
    silence = next(r for r in rec if r["kind"] == "mark")["wall"]
    last = [r for r in rec if r["kind"] == "sent"][-1]["wall"]
    brake = [r for r in rec if r["kind"] == "recv" and r["wall"] > silence]
    assert brake, rec
    assert brake[0]["wall"] - last == pytest.approx(0.4, abs=0.03)


def test_a_topic_that_appears_later_is_picked_up(ros, tmp_path):
    ros.monitor(spec(tmp_path, "entity a { rules: r: topic /late.data > 1; }\nif (a.r) then { stop; }\n"))
    time.sleep(1.0)  # the monitor subscribed long before any publisher exists
    rec = ros.probe({"listen": [{"topic": "/safety_cmd", "type": TWIST}],
                     "advertise": [{"topic": "/late", "type": "std_msgs/Int32"}],
                     "steps": [{"wait_subscribers": "/late"}, {"wait_publishers": "/safety_cmd"}, {"sleep": 0.3},
                               {"publish": "/late", "msg": {"data": 5}}, {"wait": "/safety_cmd", "timeout": 5}]})
    assert first(rec, "recv", "/safety_cmd") is not None


def test_sighup_changes_what_is_enforced_and_a_broken_spec_changes_nothing(ros, tmp_path):
    body = "entity base {{ rules: fast: topic /cmd_vel.linear.x > {} m/s; }}\nif (base.fast) then {{ brake; }}\n"
    path = spec(tmp_path, body.format(1.0))
    mon = ros.monitor(path)
    assert brake_after(ros, 2.0)
    assert not brake_after(ros, 0.5, grace=0.1)  # back under the limit: the (non-latched) brake stops
    spec(tmp_path, body.format(3.0))
    os.kill(mon.pid, signal.SIGHUP)
    wait_log(mon, ros, "rubass: reloaded")
    assert not brake_after(ros, 2.0), "the new limit is 3 m/s"
    assert brake_after(ros, 4.0)
    assert not brake_after(ros, 0.0, grace=0.1)
    (tmp_path / "s.rbs").write_text((tmp_path / "s.rbs").read_text().replace("> 3.0 m/s", "> LIMT"))
    os.kill(mon.pid, signal.SIGHUP)
    wait_log(mon, ros, "reload (SIGHUP) rejected, the previous rules keep running")
    assert "undefined name 'LIMT'" in ros.log(mon)
    assert brake_after(ros, 4.0), "the old rules still run"
    assert mon.poll() is None


def test_reload_service_reports_rejection(ros, tmp_path):
    path = spec(tmp_path, "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { brake; }\n")
    ros.monitor(path)
    (tmp_path / "s.rbs").write_text("entity a { rules: r: topic /x.data > ; }\n")
    out = ros.call("/rubass/reload")
    assert "success: False" in out.stdout and "expected expression" in out.stdout
    spec(tmp_path, "entity a { rules: r: topic /x.data > 2; }\nif (a.r) then { brake; }\n")
    out = ros.call("/rubass/reload")
    assert "success: True" in out.stdout and "1 rule, 1 behaviour" in out.stdout


def test_serial_action_writes_into_a_pty(ros, tmp_path):
    import select

    master, slave = os.openpty()
    port = os.ttyname(slave)
    lib = LIB + f'  board: {{plugin: serial, port: {port}, baud: 115200, on_start: "S\\n", on_release: "R\\n"}}\n'
    (tmp_path / "lib.yaml").write_text(lib)
    path = tmp_path / "s.rbs"
    path.write_text('import "lib.yaml";\naction primitive board;\n'
                    "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { board; }\n")
    ros.monitor(str(path))
    ros.probe({"advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
               "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.2}, {"publish": "/x", "msg": {"data": 5.0}},
                         {"sleep": 0.3}, {"publish": "/x", "msg": {"data": 0.0}}, {"sleep": 0.3}]})
    got = b""
    end = time.time() + 5
    while b"R\n" not in got and time.time() < end:
        if select.select([master], [], [], 0.2)[0]:
            got += os.read(master, 100)
    os.close(master)
    os.close(slave)
    assert got == b"S\nR\n"


def test_custom_plugin_named_in_yaml_is_called(ros, tmp_path):
    (tmp_path / "plug").mkdir()
    (tmp_path / "plug" / "myplug.py").write_text(
        "class Recorder:\n"
        "    def __init__(self, name, params):\n"
        "        self.file = params['file']\n"
        "    def start(self, ctx):\n"
        "        open(self.file, 'a').write(f'start {ctx.behaviour} {list(ctx.rules)} {list(ctx.args)}\\n')\n"
        "    def hold(self, ctx):\n"
        "        pass\n"
        "    def release(self, ctx):\n"
        "        open(self.file, 'a').write('release\\n')\n")
    ros.env["PYTHONPATH"] = str(tmp_path / "plug") + os.pathsep + ros.env["PYTHONPATH"]
    out = tmp_path / "calls.txt"
    (tmp_path / "lib.yaml").write_text(f"actions:\n  horn: {{plugin: 'myplug:Recorder', file: {out}}}\n")
    path = tmp_path / "s.rbs"
    path.write_text('import "lib.yaml";\naction primitive horn;\n'
                    'entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { horn("loud", 3); }\n')
    ros.monitor(str(path))
    ros.probe({"advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
               "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.2}, {"publish": "/x", "msg": {"data": 5.0}},
                         {"sleep": 0.3}, {"publish": "/x", "msg": {"data": 0.0}}, {"sleep": 0.5}]})
    assert out.read_text() == "start 1 ['a.r'] ['loud', 3.0]\nrelease\n"


def test_a_custom_plugin_that_cannot_be_imported_is_reported_at_its_library_place(ros, tmp_path):
    """As `rubass check` prints a library error: FILE:LINE:COL of the `plugin:` entry (it had none)."""
    lib = tmp_path / "lib.yaml"
    lib.write_text("actions:\n  horn: {plugin: log}\n  board: {plugin: no_such_mod.x:Y}\n")
    path = tmp_path / "s.rbs"
    path.write_text('import "lib.yaml";\naction primitive board;\n'
                    'entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { board; }\n')
    mon = ros.monitor(str(path))  # up, enforcing nothing
    place = f"{lib}:3:19: error: action 'board': cannot import plugin module 'no_such_mod.x'"
    wait_log(mon, ros, place)
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"wait": "/diagnostics", "timeout": 5}]})
    diag = next(r for r in rec if r["topic"] == "/diagnostics")["msg"]["status"][0]
    assert diag["level"] == 2 and "NOT ENFORCING ANY RULE: " + place in diag["message"], diag
    assert "Traceback" not in ros.log(mon)


@pytest.mark.parametrize("params,message", [
    ({}, "~spec is required"),
    ({"spec": "SPEC", "rate": "fast"}, "~rate must be a rate from 1 to 1000 Hz"),
    ({"spec": "SPEC", "queue_size": "big"}, "~queue_size must be a whole number of messages from 10 to 10000000"),
    ({"spec": "SPEC", "state_file": "' '"}, "~state_file must be the path of the latch state file"),
    ({"spec": "SPEC", "nice": "high"}, "~nice must be a whole number from -20 (highest priority) to 19"),
    ({"spec": "SPEC", "nice": "null"}, "~nice: null is no parameter value"),  # was rospy's traceback
])  # a missing or broken spec or library keeps the monitor up, not enforcing: test_reliability_latch.py
def test_bad_params_exit_non_zero_before_subscribing(ros, tmp_path, params, message):
    good = spec(tmp_path, "entity a { rules: r: topic /watched.data > 1; }\nif (a.r) then { stop; }\n")
    broken = spec(tmp_path, "entity a { rules: r: topic /watched.data > LIMT; }\nif (a.r) then { stop; }\n",
                  name="broken.rbs")
    (tmp_path / "badlib").mkdir()
    badlib = spec(tmp_path / "badlib", "entity a { rules: r: topic /watched.data > 1; }\nif (a.r) then { stop; }\n",
                  lib=LIB.replace("geometry_msgs/Twist", "geometry_msgs/Twst"))
    subst = {"SPEC": good, "BROKEN": broken, "BADLIB": badlib}
    args = [PY, os.path.join(ROOT, "scripts", "monitor")] + [f"_{k}:={subst.get(v, v)}" for k, v in params.items()]
    proc = subprocess.run(args, env=ros.env, capture_output=True, text=True, timeout=30)
    assert proc.returncode == 1
    assert message in proc.stderr, proc.stderr
    assert "Traceback" not in proc.stderr
    import rosgraph
    state = rosgraph.Master("/t", master_uri=ros.env["ROS_MASTER_URI"]).getSystemState()
    assert not [t for t, _ in state[1] if t == "/watched"]  # never subscribed


def test_sigterm_releases_non_latched_actions_and_exits_0(ros, tmp_path):
    """...and reports each release on ~events (cause "shutdown"), so every start there has its release."""
    lib = LIB.replace("message: {data: true}, rate: 20 Hz}", "message: {data: true}, on_release: {data: false}, rate: 20 Hz}")
    mon = ros.monitor(spec(tmp_path, "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { brake; }\n", lib=lib))
    listener = ros.probe_bg({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"},
                                        {"topic": "/rubass/events", "type": "std_msgs/String"}],
                             "advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
                             "steps": [{"wait_subscribers": "/x"}, {"wait_publishers": "/brake"}, {"sleep": 0.3},
                                       {"publish": "/x", "msg": {"data": 5.0}}, {"sleep": 0.5}, {"mark": "active"},
                                       {"sleep": 3.0}]}, name="listener")
    seen = []
    while True:
        line = listener.stdout.readline()
        seen.append(line)
        if '"active"' in line or not line:
            break
    assert any('"recv"' in line for line in seen), "the brake was active before the signal"
    mon.send_signal(signal.SIGTERM)
    assert mon.wait(10) == 0, ros.log(mon)
    rec = [json.loads(line) for line in seen if line.startswith("{")] + records(listener)
    assert [r["msg"]["data"] for r in rec if r["kind"] == "recv" and r["topic"] == "/brake"][-1] is False, ros.log(mon)
    events = [json.loads(r["msg"]["data"]) for r in rec if r["kind"] == "recv" and r["topic"] == "/rubass/events"]
    assert [(e["event"], e["cause"]) for e in events] == [("start", "message on /x"), ("release", "shutdown")], events


def test_a_missing_field_is_an_error_in_log_and_status_and_the_monitor_keeps_running(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, "entity a { rules: r: topic /x.data > 1; q: topic /y.data > 1; }\n"
                                     "if (a.r or a.q) then { brake; }\n"))
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"},
                                {"topic": "/brake", "type": "std_msgs/Bool"}],
                     "advertise": [{"topic": "/x", "type": "geometry_msgs/Twist"},
                                   {"topic": "/y", "type": "std_msgs/Float64"}],
                     "steps": [{"wait_subscribers": "/x"}, {"wait_subscribers": "/y"}, {"sleep": 0.2},
                               {"publish": "/x", "msg": {"linear": {"x": 5.0}}}, {"sleep": 1.5},
                               {"publish": "/y", "msg": {"data": 5.0}}, {"wait": "/brake", "timeout": 5}],
                     "linger": 0.2})
    assert "rule 'a.r' reads /x.data, but in geometry_msgs/Twist: geometry_msgs/Twist has no field 'data'" \
        in ros.log(mon)
    diags = [r["msg"] for r in rec if r.get("topic") == "/diagnostics"]
    entity = [s for d in diags for s in d["status"] if s["name"] == "rubass: a"][-1]
    assert entity["level"] == 2
    assert any("has no field 'data'" in v["value"] for v in entity["values"])
    assert any(r["topic"] == "/brake" for r in rec if r["kind"] == "recv"), "a.q still enforced"
    assert mon.poll() is None


def test_events_report_cause_rules_and_latency_and_heartbeat_runs_at_the_tick_rate(ros, tmp_path):
    ros.monitor(spec(tmp_path, "entity a { rules: r: topic /x.data > 1; w: (topic /x.data > 1) for 0.2 s; }\n"
                               "if (a.r) then { brake; }\nif (a.w) then { warn; }\n"), rate=50)
    rec = ros.probe({"listen": [{"topic": "/rubass/events", "type": "std_msgs/String"},
                                {"topic": "/rubass/heartbeat", "type": "std_msgs/Header"}],
                     "advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
                     "steps": [{"wait_subscribers": "/x"}, {"wait_publishers": "/rubass/events"}, {"sleep": 0.3},
                               {"mark": "hb"}, {"sleep": 1.0}, {"mark": "hb_end"},
                               {"publish": "/x", "msg": {"data": 5.0}}, {"sleep": 0.4},
                               {"publish": "/x", "msg": {"data": 0.0}}, {"sleep": 0.3}]})
    import json

    events = [json.loads(r["msg"]["data"]) for r in rec if r.get("topic") == "/rubass/events"]
    assert [(e["event"], e["behaviour"]) for e in events] == [("start", 1), ("start", 2), ("release", 1), ("release", 2)]
    assert events[0]["cause"] == "message on /x" and events[0]["rules"] == ["a.r"] and events[0]["actions"] == ["brake"]
    assert 0 <= events[0]["latency_ms"] < 50
    assert events[1]["cause"] == "deadline" and events[1]["time"] == pytest.approx(events[0]["time"] + 0.2, abs=1e-6)
    marks = {r["name"]: r["wall"] for r in rec if r["kind"] == "mark"}
    beats = [r for r in rec if r.get("topic") == "/rubass/heartbeat" and marks["hb"] <= r["wall"] <= marks["hb_end"]]
    assert 45 <= len(beats) <= 55


def test_reset_releases_a_latched_stop_once_its_cause_is_gone(ros, tmp_path):
    ros.monitor(spec(tmp_path, "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { stop; }\n"))
    ros.probe({"advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
               "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.2}, {"publish": "/x", "msg": {"data": 5.0}},
                         {"sleep": 0.3}]})
    assert "latched and still active (cause present)" in ros.call("/rubass/reset").stdout  # (yaml wraps it)
    ros.probe({"advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
               "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.2}, {"publish": "/x", "msg": {"data": 0.0}},
                         {"sleep": 0.3}]})
    still = ros.probe({"listen": [{"topic": "/safety_cmd", "type": TWIST}], "steps": [{"sleep": 0.5}]})
    assert len([r for r in still if r["kind"] == "recv"]) >= 5, "latched: still stopping after the cause went"
    assert "released 1 latched behaviour" in ros.call("/rubass/reset").stdout
    after = ros.probe({"listen": [{"topic": "/safety_cmd", "type": TWIST}], "steps": [{"sleep": 0.5}]})
    assert not [r for r in after if r["kind"] == "recv"]


def test_service_action_calls_the_service_and_a_hung_one_times_out_without_blocking(ros, tmp_path):
    lib = LIB + ("  brake_srv: {plugin: service, service: /base/brake, type: std_srvs/Trigger, timeout: 0.3 s}\n"
                 "  hung_srv: {plugin: service, service: /base/hung, type: std_srvs/Trigger, timeout: 0.3 s}\n"
                 "  missing_srv: {plugin: service, service: /base/missing, type: std_srvs/Trigger, timeout: 0.3 s}\n")
    (tmp_path / "lib.yaml").write_text(lib)
    path = tmp_path / "s.rbs"
    path.write_text('import "lib.yaml";\naction primitive brake_srv, hung_srv, missing_srv, brake;\n'
                    "entity a { rules: r: topic /x.data > 1; }\n"
                    "if (a.r) then { hung_srv; brake_srv; missing_srv; brake; }\n")
    mon = ros.monitor(str(path))
    rec = ros.probe({"serve": [{"service": "/base/brake", "type": "std_srvs/Trigger"},
                               {"service": "/base/hung", "type": "std_srvs/Trigger", "delay": 30}],
                     "listen": [{"topic": "/brake", "type": "std_msgs/Bool"}],
                     "advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
                     "steps": [{"wait_subscribers": "/x"}, {"wait_publishers": "/brake"}, {"sleep": 0.3},
                               {"publish": "/x", "msg": {"data": 5.0}}, {"sleep": 1.5}]}, timeout=90)
    sent = next(r["wall"] for r in rec if r["kind"] == "sent")
    calls = [r for r in rec if r["kind"] == "call"]
    assert [c["topic"] for c in calls if c["topic"] == "/base/brake"] == ["/base/brake"]
    assert next(c["wall"] for c in calls if c["topic"] == "/base/brake") - sent < 0.2
    brake = next(r["wall"] for r in rec if r["kind"] == "recv")
    assert brake - sent < 0.1, "the hung service did not delay the other actions"
    assert "action 'hung_srv' start failed" in ros.log(mon) and "did not answer within 0.3 s" in ros.log(mon)
    # a service nobody advertises is not a timeout: it says so (it said "did not answer within 0.3 s")
    assert "service /base/missing does not exist (not advertised on the master)" in ros.log(mon), ros.log(mon)
    assert "/base/missing did not answer" not in ros.log(mon)


def test_a_node_hung_with_sigstop_is_not_alive_within_a_sample_and_its_timeout(ros, tmp_path):
    victim = ros.probe_bg({"node": "victim", "anonymous": False, "steps": [{"sleep": 60}]}, name="victim")
    mon = ros.monitor(spec(tmp_path, "entity n: /victim { rules: dead: not alive(node /victim); }\n"
                                     "if (n.dead) then { stop; }\n"), node_rate=10)
    listener = listen_until_stopped(ros, "/safety_cmd", TWIST)
    time.sleep(0.5)
    hung = time.time()
    os.kill(victim.pid, signal.SIGSTOP)  # it keeps its sockets: only the getPid timeout finds it
    try:
        rec = records(listener)
    finally:
        os.kill(victim.pid, signal.SIGCONT)
    stop = first(rec, "recv", "/safety_cmd")
    assert stop is not None, ros.log(mon)
    assert 0 < stop["wall"] - hung < 0.1 + 0.1 + 0.1 + 0.05  # a sample, the 100 ms timeout, +100 ms, slack


def test_a_storm_of_sighups_costs_at_most_two_reloads_and_the_newest_spec_wins(ros, tmp_path):
    filler = "".join(f"  f{i}: (topic /filler_{i % 20}.data > {i}) for 1 s;\n" for i in range(1000))
    body = ("entity base {{ rules: fast: topic /cmd_vel.linear.x > {} m/s; }}\nentity filler {{ rules:\n" + filler +
            "}}\nif (base.fast) then {{ brake; }}\n")
    mon = ros.monitor(spec(tmp_path, body.format(1.0)))
    wait_log(mon, ros, "rubass: enforcing", timeout=30.0)  # its 1,000 rules are checked after ~reset is up
    for limit in range(2, 22):  # rewritten in place (truncated first), as a script would
        spec(tmp_path, body.format(float(limit)))
        os.kill(mon.pid, signal.SIGHUP)
        time.sleep(0.01)
    spec(tmp_path, body.format(3.0))
    os.kill(mon.pid, signal.SIGHUP)
    time.sleep(6.0)
    log = ros.log(mon)
    assert 1 <= log.count("rubass: reloaded") <= 3, log
    assert "reloaded" in log and ": 0 rules" not in log
    assert not brake_after(ros, 2.0), "the newest spec (3 m/s) is enforced"
    assert brake_after(ros, 4.0)


def test_a_reload_that_would_drop_every_behaviour_is_refused(ros, tmp_path):
    path = spec(tmp_path, "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { brake; }\n")
    mon = ros.monitor(path)
    (tmp_path / "s.rbs").write_text("")  # an empty file is a valid spec: it must not become the rules
    out = ros.call("/rubass/reload")
    assert "success: False" in out.stdout and "refusing to drop every safety behaviour" in out.stdout
    assert mon.poll() is None


def test_a_plain_rosrun_is_the_node_the_readme_names(ros, tmp_path):
    """`rosrun rubass monitor _spec:=…` with no __name: the node is /rubass, as the launch file
    and the README's `rosservice call /rubass/reload` say, and `~x` is /rubass/x."""
    path = spec(tmp_path, "entity a { rules: r: topic ~x.data > 1; }\nif (a.r) then { stop; }\n")
    mon = ros.spawn([PY, os.path.join(ROOT, "scripts", "monitor"), f"_spec:={path}"], "monitor-plain")
    ros.wait_service("/rubass/reload", mon)
    ros.wait_service("/rubass/reset", mon)
    rec = ros.probe({"listen": [{"topic": "/safety_cmd", "type": TWIST}],
                     "advertise": [{"topic": "/rubass/x", "type": "std_msgs/Float64"}],
                     "steps": [{"wait_subscribers": "/rubass/x"}, {"wait_publishers": "/safety_cmd"}, {"sleep": 0.3},
                               {"publish": "/rubass/x", "msg": {"data": 2.0}},
                               {"wait": "/safety_cmd", "timeout": 5}]})
    assert first(rec, "recv", "/safety_cmd") is not None, ros.log(mon)
