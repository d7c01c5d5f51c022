"""The `limit` action on a live ROS 1 system (LANGUAGE.md §16): real publishers, real subscribers."""
import os
import time

import pytest

from conftest import ROOT
from rosharness import PY, TWIST

pytestmark = [pytest.mark.ros, pytest.mark.slow]

STAMPED = "geometry_msgs/TwistStamped"
DIAG = "diagnostic_msgs/DiagnosticArray"
ZERO = {"x": 0.0, "y": 0.0, "z": 0.0}


def limit_spec(tmp_path, lib, actions="crawl", triggers=(("on", "/trig", "crawl"),)):
    (tmp_path / "lib.yaml").write_text(lib)
    rules = " ".join(f"{name}: topic {topic}.data > 0;" for name, topic, _ in triggers)
    body = "".join(f"if (t.{name}) then {{ {action}; }}\n" for name, _, action in triggers)
    path = tmp_path / "s.rbs"
    path.write_text(f'import "lib.yaml";\naction primitive {actions};\nentity t {{ rules: {rules} }}\n' + body)
    return str(path)


def between(rec, lo, hi, topic="/safety_cmd"):
    return [r for r in rec if r["kind"] == "recv" and r["topic"] == topic and lo <= r["wall"] < hi]


def mark(rec, name):
    return next(r["wall"] for r in rec if r["kind"] == "mark" and r["name"] == name)


def sent(rec, topic, nth=-1):
    return [r for r in rec if r["kind"] == "sent" and r["topic"] == topic][nth]["wall"]


CRAWL = ("actions:\n  crawl:\n    plugin: limit\n    input: /cmd_vel\n    topic: /safety_cmd\n"
         "    linear_x: [-0.1 m/s, 0.2 m/s]\n    angular_z: [-0.5 rad/s, 0.5 rad/s]\n")


def test_limit_clamps_while_active_publishes_zero_after_timeout_and_nothing_while_inactive(ros, tmp_path):
    ros.monitor(limit_spec(tmp_path, CRAWL))
    fast = {"linear": {"x": 1.0, "y": 0.7}, "angular": {"z": -2.0}}
    rec = ros.probe({
        "listen": [{"topic": "/safety_cmd", "type": TWIST}],
        "advertise": [{"topic": "/cmd_vel", "type": TWIST}, {"topic": "/trig", "type": "std_msgs/Float64"}],
        "steps": [{"wait_subscribers": "/cmd_vel"}, {"wait_subscribers": "/trig"}, {"wait_publishers": "/safety_cmd"},
                  {"sleep": 0.5}, {"mark": "inactive"},
                  {"publish": "/cmd_vel", "msg": fast, "repeat": 6, "period": 0.05},
                  {"publish": "/trig", "msg": {"data": 1.0}}, {"sleep": 0.2}, {"mark": "active"},
                  {"publish": "/cmd_vel", "msg": fast, "repeat": 6, "period": 0.05},
                  {"publish": "/cmd_vel", "msg": {"linear": {"x": 0.05}, "angular": {"z": 0.3}}},
                  {"sleep": 1.2}, {"mark": "resume"},
                  {"publish": "/cmd_vel", "msg": {"linear": {"x": -1.0}}}, {"sleep": 0.2},
                  {"publish": "/trig", "msg": {"data": 0.0}}, {"sleep": 0.2}, {"mark": "released"},
                  {"publish": "/cmd_vel", "msg": fast, "repeat": 10, "period": 0.05}, {"sleep": 0.8}],
        "linger": 0.1})
    t_on = sent(rec, "/trig", 0)
    # inactive: commands flow, nothing is published
    assert between(rec, 0, t_on) == []
    # the start republishes the latest command (0.05 s old, fresh) clamped at once
    first = between(rec, t_on, t_on + 1)[0]
    assert first["wall"] - t_on < 0.1 and first["msg"]["linear"]["x"] == 0.2
    # every command while active comes out clamped on the named axes, the others untouched (and
    # the latest again at 20 Hz when none came within a period: a mux's input stays alive)
    active = between(rec, mark(rec, "active"), sent(rec, "/cmd_vel", 12) + 0.3)  # zeros only 0.5 s after the last
    xs = [m["msg"]["linear"]["x"] for m in active]
    assert len(active) >= 7 and set(xs[:6]) == {0.2} and xs[-1] == 0.05, active
    assert [x for i, x in enumerate(xs) if i == 0 or x != xs[i - 1]] == [0.2, 0.05]
    assert {m["msg"]["angular"]["z"] for m in active if m["msg"]["linear"]["x"] == 0.2} == {-0.5}
    assert all(m["msg"]["linear"]["y"] == pytest.approx(0.7) for m in active if m["msg"]["linear"]["x"] == 0.2)
    # no command for 0.5 s: the last one again at 20 Hz meanwhile, then zero, at 20 Hz, until a command comes again
    last_cmd = sent(rec, "/cmd_vel", 12)
    after = between(rec, last_cmd + 0.01, mark(rec, "resume"))
    repeats = [m for m in after if m["msg"]["linear"]["x"] == 0.05]
    silence = after[len(repeats):]
    assert all(m["wall"] - last_cmd < 0.55 for m in repeats) and 5 <= len(repeats) <= 11, after
    assert silence and all(m["msg"] == {"linear": ZERO, "angular": ZERO} for m in silence), silence
    assert 0.45 <= silence[0]["wall"] - last_cmd <= 0.65
    assert 9 <= len(silence) <= 16  # 0.5 s of 1 s silence... at 20 Hz: ~14
    gaps = [b["wall"] - a["wall"] for a, b in zip(silence, silence[1:])]
    assert max(gaps) < 0.12 and sorted(gaps)[len(gaps) // 2] == pytest.approx(0.05, abs=0.01)
    resumed = between(rec, sent(rec, "/cmd_vel", 13), sent(rec, "/trig", 1))
    first = next(i for i, m in enumerate(resumed) if m["msg"]["linear"]["x"] == -0.1)  # a zero may precede it
    assert first <= 1 and resumed[first]["wall"] - sent(rec, "/cmd_vel", 13) < 0.1
    # then that command again at 20 Hz, and no zero: 0.2 s is no timeout
    assert [m["msg"]["linear"]["x"] for m in resumed[first:]] == [-0.1] * (len(resumed) - first)
    assert 2 <= len(resumed) - first <= 6, resumed
    # released: nothing more, whatever comes in
    assert between(rec, sent(rec, "/trig", 1) + 0.05, 1e12) == []


def test_a_planner_slower_than_the_rate_is_repeated_so_a_mux_keeps_the_safety_input(ros, tmp_path):
    """Acceptance finding: with a 4 Hz planner the limit published at 4 Hz (gaps of 0.25 s), so
    twist_mux's documented 0.2 s timeout on the safety input would let the unclamped planner
    through between commands. The latest fresh command is now repeated at `rate` (20 Hz)."""
    ros.monitor(limit_spec(tmp_path, CRAWL))
    fast = {"linear": {"x": 1.0}, "angular": {"z": -2.0}}
    rec = ros.probe({
        "listen": [{"topic": "/safety_cmd", "type": TWIST}],
        "advertise": [{"topic": "/cmd_vel", "type": TWIST}, {"topic": "/trig", "type": "std_msgs/Float64"}],
        "steps": [{"wait_subscribers": "/cmd_vel"}, {"wait_subscribers": "/trig"}, {"wait_publishers": "/safety_cmd"},
                  {"sleep": 0.5}, {"publish": "/trig", "msg": {"data": 1.0}}, {"sleep": 0.2}, {"mark": "active"},
                  {"publish": "/cmd_vel", "msg": fast, "repeat": 8, "period": 0.25}, {"mark": "end"}],
        "linger": 0.1})
    out = between(rec, sent(rec, "/cmd_vel", 0) + 0.01, mark(rec, "end"))
    assert len(out) >= 25, out  # 1.75 s at 20 Hz: ~35 (at the planner's 4 Hz it was 7)
    assert all(m["msg"]["linear"]["x"] == 0.2 and m["msg"]["angular"]["z"] == -0.5 for m in out), out
    gaps = [b["wall"] - a["wall"] for a, b in zip(out, out[1:])]
    assert max(gaps) < 0.15, gaps  # under twist_mux's 0.2 s safety timeout


def test_limit_on_twist_stamped_keeps_the_header(ros, tmp_path):
    lib = CRAWL.replace("topic: /safety_cmd\n", f"topic: /safety_cmd\n    type: {STAMPED}\n    timeout: 0.3 s\n"
                                                  "    rate: 10 Hz\n")
    ros.monitor(limit_spec(tmp_path, lib))
    cmd = {"header": {"frame_id": "base_link", "seq": 7}, "twist": {"linear": {"x": 3.0}, "angular": {"z": 0.1}}}
    rec = ros.probe({
        "listen": [{"topic": "/safety_cmd", "type": STAMPED}],
        "advertise": [{"topic": "/cmd_vel", "type": STAMPED}, {"topic": "/trig", "type": "std_msgs/Float64"}],
        "steps": [{"wait_subscribers": "/cmd_vel"}, {"wait_subscribers": "/trig"}, {"wait_publishers": "/safety_cmd"},
                  {"sleep": 0.5}, {"publish": "/trig", "msg": {"data": 1.0}}, {"sleep": 0.5}, {"mark": "cmd"},
                  {"publish": "/cmd_vel", "msg": cmd}, {"sleep": 0.6}],
        "linger": 0.1})
    t_on = sent(rec, "/trig", 0)
    at_start = between(rec, t_on, mark(rec, "cmd"))
    assert at_start and at_start[0]["wall"] - t_on < 0.1  # nothing came yet: zero at once, then at 10 Hz
    assert all(m["msg"]["twist"]["linear"] == ZERO for m in at_start)
    assert all(m["msg"]["header"]["stamp"]["secs"] > 0 for m in at_start)  # stamped now
    after = between(rec, mark(rec, "cmd"), 1e12)
    got = next(i for i, m in enumerate(after) if m["msg"]["header"]["frame_id"] == "base_link")
    assert got <= 1 and after[got]["wall"] - sent(rec, "/cmd_vel") < 0.1  # a zero may just precede it
    assert after[got]["msg"]["twist"]["linear"]["x"] == 0.2 and after[got]["msg"]["twist"]["angular"]["z"] == 0.1
    repeats = [m for m in after[got + 1:] if m["wall"] - after[got]["wall"] < 0.25]  # at 10 Hz, as it came
    assert all(m["msg"]["header"]["frame_id"] == "base_link" and m["msg"]["twist"]["linear"]["x"] == 0.2
               for m in repeats), repeats
    zeros = [m for m in after[got + 1:] if m["wall"] - after[got]["wall"] > 0.35]  # its timeout is 0.3 s
    assert zeros and all(m["msg"]["twist"]["linear"] == ZERO for m in zeros)


def test_a_mistyped_input_is_no_command_so_the_limit_publishes_zero_and_logs_why(ros, tmp_path):
    mon = ros.monitor(limit_spec(tmp_path, CRAWL))
    rec = ros.probe({
        "listen": [{"topic": "/safety_cmd", "type": TWIST}, {"topic": "/diagnostics", "type": DIAG}],
        "advertise": [{"topic": "/cmd_vel", "type": STAMPED}, {"topic": "/trig", "type": "std_msgs/Float64"}],
        "steps": [{"wait_subscribers": "/cmd_vel"}, {"wait_subscribers": "/trig"}, {"wait_publishers": "/safety_cmd"},
                  {"sleep": 0.5}, {"publish": "/trig", "msg": {"data": 1.0}},
                  {"publish": "/cmd_vel", "msg": {"twist": {"linear": {"x": 3.0}}}, "repeat": 20, "period": 0.05},
                  {"sleep": 1.2}],
        "linger": 0.1})
    got = between(rec, sent(rec, "/trig", 0), sent(rec, "/cmd_vel") + 0.05)
    assert len(got) >= 10 and all(m["msg"] == {"linear": ZERO, "angular": ZERO} for m in got)
    text = "/cmd_vel carries geometry_msgs/TwistStamped, not geometry_msgs/Twist"
    log = ros.log(mon)
    assert f"action 'crawl': {text}" in log, log
    last = [r for r in rec if r["kind"] == "recv" and r["topic"] == "/diagnostics"][-1]["msg"]
    values = {v["key"]: v["value"] for st in last["status"] for v in st["values"]}
    assert text in values.get("action crawl", ""), values


@pytest.mark.parametrize("lib, message", [
    (CRAWL.replace("[-0.1 m/s, 0.2 m/s]", "[0.3 m/s, 0.2 m/s]"),
     "lib.yaml:6:15: error: action 'crawl': 'linear_x': min '0.3 m/s' is greater than max '0.2 m/s'"),
    (CRAWL.replace("[-0.1 m/s, 0.2 m/s]", "[-0.1, 0.2]"),
     "lib.yaml:6:15: error: action 'crawl': 'linear_x': -0.1 needs a unit (m/s, cm/s or km/h)"),
    (CRAWL + "    type: std_msgs/String\n",
     "lib.yaml:8:11: error: action 'crawl': 'type' must be one of geometry_msgs/Twist, geometry_msgs/TwistStamped"),
])
def test_a_bad_limit_is_refused_before_the_monitor_subscribes_or_publishes(ros, tmp_path, lib, message):
    out = refused(ros, limit_spec(tmp_path, lib))
    assert message in out, out


def refused(ros, spec, *params):
    """Start a monitor on a spec it must refuse: it exits 1, or stays up enforcing nothing; either
    way it says why, with no traceback, and never subscribes to the spec's topics nor publishes."""
    proc = ros.spawn([PY, os.path.join(ROOT, "scripts", "monitor"), f"_spec:={spec}"] + list(params), "refused")
    end = time.time() + 30
    while proc.poll() is None and "NOT ENFORCING" not in ros.log(proc) and time.time() < end:
        time.sleep(0.1)
    out = ros.log(proc)
    assert proc.returncode in (None, 1) and ("NOT ENFORCING" in out or "cannot start" in out), out
    assert "Traceback" not in out
    import rosgraph
    state = rosgraph.Master("/t", master_uri=ros.env["ROS_MASTER_URI"]).getSystemState()
    assert not [t for t, _ in state[1] if t in ("/trig", "/cmd_vel", "/a", "/b")], state
    assert not [t for t, _ in state[0] if t == "/safety_cmd"], state
    return out


def test_a_reload_that_changes_a_limit_applies_the_new_range_without_a_gap_or_a_second_publisher(ros, tmp_path):
    import signal

    from rosharness import records

    mon = ros.monitor(limit_spec(tmp_path, CRAWL))
    cmd = {"linear": {"x": 1.0}}
    trigger = ros.probe_bg({"advertise": [{"topic": "/trig", "type": "std_msgs/Float64"}],
                            "steps": [{"wait_subscribers": "/trig"},
                                      {"publish": "/trig", "msg": {"data": 1.0}, "repeat": 400, "period": 0.02}]},
                           name="trigger")
    listener = ros.probe_bg({
        "listen": [{"topic": "/safety_cmd", "type": TWIST}],
        "advertise": [{"topic": "/cmd_vel", "type": TWIST}],
        "steps": [{"wait_subscribers": "/cmd_vel"}, {"wait_publishers": "/safety_cmd"}, {"sleep": 0.5},
                  {"mark": "go"}, {"publish": "/cmd_vel", "msg": cmd, "repeat": 80, "period": 0.05}],
        "linger": 0.1}, name="listener")
    head = []
    while '"go"' not in (head[-1] if head else ""):  # zeros come before: active, no command yet
        head.append(listener.stdout.readline())
        assert head[-1], head
    time.sleep(1.0)
    (tmp_path / "lib.yaml").write_text(CRAWL.replace("0.2 m/s]", "0.3 m/s]"))
    time.sleep(0.1)
    mon.send_signal(signal.SIGHUP)
    out = records(listener)
    trigger.kill()
    assert "reloaded" in ros.log(mon), ros.log(mon)
    got = [r for r in out if r["kind"] == "recv"]
    got = got[[m["msg"]["linear"]["x"] for m in got].index(0.2):]  # from the first command's output on
    xs = [m["msg"]["linear"]["x"] for m in got]
    assert xs[0] == 0.2 and xs[-1] == 0.3, xs
    switch = xs.index(0.3)
    assert set(xs[:switch]) == {0.2} and set(xs[switch:]) == {0.3}, xs  # one range, then the other: no zero
    # one output per command, and the latest again where the planner was a period late: no second
    # publisher (it would double the count), no zeros
    assert 75 <= len(got) <= 100, len(got)
    gaps = [b["wall"] - a["wall"] for a, b in zip(got, got[1:])]
    assert max(gaps) < 0.3, gaps
