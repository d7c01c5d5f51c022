"""Issue 13 (1, 6, 7): a latched stop goes on across a reload of its action library, survives the
monitor's own death until ~reset, and a spec that cannot be used at start leaves the monitor up,
ERROR, without heartbeat, until a reload brings a good one."""
import json
import os
import signal
import time

import pytest
from rosharness import LIB, TWIST, spec, wait_log

pytestmark = [pytest.mark.ros, pytest.mark.slow]

BODY = "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { stop; }\n"


def trigger_and_clear(ros):
    """A violation then its end: the latched stop stays."""
    ros.probe({"advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
               "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.3}, {"publish": "/x", "msg": {"data": 5.0}},
                         {"sleep": 0.3}, {"publish": "/x", "msg": {"data": 0.0}}, {"sleep": 0.2}]})


def stops_within(ros, seconds, name="stops"):
    """The /safety_cmd messages received during `seconds` (after the subscription connected)."""
    rec = ros.probe({"listen": [{"topic": "/safety_cmd", "type": TWIST}],
                     "steps": [{"sleep": 0.5}, {"mark": "go"}, {"sleep": seconds}]})
    go = next(r["wall"] for r in rec if r["kind"] == "mark")
    return [r["wall"] for r in rec if r["kind"] == "recv" and r["wall"] >= go]


def test_a_latched_stop_goes_on_without_a_gap_when_its_action_library_is_edited_and_reloaded(ros, tmp_path):
    path = spec(tmp_path, BODY)
    mon = ros.monitor(path)
    listener = ros.probe_bg({"listen": [{"topic": "/safety_cmd", "type": TWIST}],
                             "steps": [{"sleep": 0.5}, {"mark": "listening"}, {"sleep": 12.0}]}, name="listener")
    assert '"listening"' in listener.stdout.readline()
    trigger_and_clear(ros)
    time.sleep(0.5)
    (tmp_path / "lib.yaml").write_text(LIB.replace("rate: 20 Hz, latch: true", "rate: 10 Hz, latch: true"))
    time.sleep(0.1)
    reload_at = time.time()
    os.kill(mon.pid, signal.SIGHUP)
    wait_log(mon, ros, "reloaded")
    time.sleep(3.0)
    os.killpg(listener.pid, signal.SIGTERM)
    out, _ = listener.communicate(timeout=20)
    walls = [json.loads(line)["wall"] for line in out.splitlines() if '"recv"' in line]
    around = [w for w in walls if w > reload_at - 1.0]
    assert around and around[-1] > reload_at + 2.5, f"the stop ceased at the reload:\n{ros.log(mon)}"
    gaps = [b - a for a, b in zip(around, around[1:])]
    assert max(gaps) < 0.3, f"a gap of {max(gaps):.3f} s (one period is 0.1 s)"
    after = [w for w in walls if reload_at + 1.0 < w < reload_at + 3.0]
    assert 12 <= len(after) <= 26, f"{len(after)} in 2 s: the new rate (10 Hz) is used"
    assert mon.poll() is None


def test_a_latched_stop_survives_the_monitors_death_until_reset(ros, tmp_path):
    path = spec(tmp_path, BODY)
    mon = ros.monitor(path)
    trigger_and_clear(ros)
    state = tmp_path / "ros_home" / "rubass" / f"rubass.{ros.port}.latches.json"  # keyed by the master's port
    assert "stop" in json.loads(state.read_text())["latched"][0]["actions"], "written under $ROS_HOME by default"
    os.killpg(mon.pid, signal.SIGKILL)
    mon.wait(10)
    mon2 = ros.monitor(path)  # as respawn="true" does; no violation any more
    assert len(stops_within(ros, 1.0)) >= 10, f"the latched stop is active again (20 Hz):\n{ros.log(mon2)}"
    wait_log(mon2, ros, "active again until ~reset")
    out = ros.call("/rubass/reset")
    assert out.returncode == 0 and "released" in out.stdout, out.stdout + out.stderr
    time.sleep(0.3)
    assert stops_within(ros, 1.0) == [], "released by ~reset"
    assert json.loads(state.read_text())["latched"] == []
    mon2.send_signal(signal.SIGTERM)
    mon2.wait(20)
    ros.monitor(path)  # a third start after the reset: nothing to restore
    assert stops_within(ros, 1.0) == []


@pytest.mark.parametrize("content", [b"{\"format\": \"rubass-latches\", \"latched\": [{\"holder\": \"x\", \"act",
                                     b"\x00\xff garbage"])
def test_a_corrupt_state_file_is_reported_and_holds_the_actions_it_names(ros, tmp_path, content):
    path = spec(tmp_path, BODY)
    state = tmp_path / "state.json"
    state.write_bytes(content + (b" stop" if b"act" in content else b""))
    mon = ros.monitor(path, state_file=str(state))
    assert len(stops_within(ros, 1.0)) >= 10, ros.log(mon)  # the named 'stop' (or every latched action)
    wait_log(mon, ros, "is corrupt or foreign")
    assert ros.call("/rubass/reset").returncode == 0
    time.sleep(0.3)
    assert stops_within(ros, 1.0) == []


def test_a_missing_spec_at_start_keeps_the_monitor_up_silent_and_a_reload_makes_it_enforce(ros, tmp_path):
    path = tmp_path / "s.rbs"
    mon = ros.monitor(str(path))  # waits for the services: the monitor is up
    rec = ros.probe({"listen": [{"topic": "/rubass/heartbeat", "type": "std_msgs/Header"},
                                {"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"wait": "/diagnostics", "timeout": 5}, {"sleep": 1.0}]})
    assert not [r for r in rec if r["topic"] == "/rubass/heartbeat"], "no heartbeat while not enforcing"
    diag = next(r for r in rec if r["topic"] == "/diagnostics")["msg"]["status"][0]
    assert diag["level"] == 2 and str(path) in diag["message"] and "NOT ENFORCING" in diag["message"], diag
    assert mon.poll() is None
    out = ros.call("/rubass/reset")
    assert "not enforcing" in out.stdout, out.stdout
    spec(tmp_path, BODY)  # the file appears (with its library)
    time.sleep(0.1)
    out = ros.call("/rubass/reload")
    assert "enforcing" in out.stdout and "True" in out.stdout, out.stdout
    rec = ros.probe({"listen": [{"topic": "/rubass/heartbeat", "type": "std_msgs/Header"},
                                {"topic": "/safety_cmd", "type": TWIST}],
                     "advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
                     "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.3}, {"publish": "/x", "msg": {"data": 5.0}},
                               {"wait": "/safety_cmd", "timeout": 3}]})
    assert [r for r in rec if r["topic"] == "/rubass/heartbeat"], ros.log(mon)
    assert [r for r in rec if r["topic"] == "/safety_cmd" and r["kind"] == "recv"], ros.log(mon)


def test_a_broken_spec_at_start_is_named_in_diagnostics_and_a_sighup_after_the_fix_enforces(ros, tmp_path):
    path = spec(tmp_path, BODY.replace("> 1", "> LIMT"))
    mon = ros.monitor(path)
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"wait": "/diagnostics", "timeout": 5}]})
    diag = next(r for r in rec if r["topic"] == "/diagnostics")["msg"]["status"][0]
    assert diag["level"] == 2 and "undefined name 'LIMT'" in json.dumps(diag), diag
    spec(tmp_path, BODY)
    time.sleep(0.1)
    os.kill(mon.pid, signal.SIGHUP)
    wait_log(mon, ros, "rubass: enforcing")
    rec = ros.probe({"listen": [{"topic": "/safety_cmd", "type": TWIST}],
                     "advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
                     "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.3}, {"publish": "/x", "msg": {"data": 5.0}},
                               {"wait": "/safety_cmd", "timeout": 3}]})
    assert [r for r in rec if r["kind"] == "recv"], ros.log(mon)


def test_a_reload_that_would_drop_a_latched_active_action_is_rejected_and_the_stop_goes_on(ros, tmp_path):
    path = spec(tmp_path, BODY)
    mon = ros.monitor(path)
    trigger_and_clear(ros)
    (tmp_path / "lib.yaml").write_text(LIB.replace("  stop:", "  halt:"))
    (tmp_path / "s.rbs").write_text('import "lib.yaml";\naction primitive halt, brake, warn;\n'
                                    + BODY.replace("stop", "halt"))
    time.sleep(0.1)
    out = ros.call("/rubass/reload")
    assert "no longer declares stop, which is latched and active" in out.stdout, out.stdout
    assert len(stops_within(ros, 1.0)) >= 10, "the latched stop goes on"
    assert ros.call("/rubass/reset").returncode == 0
    out = ros.call("/rubass/reload")
    assert "reloaded" in out.stdout, out.stdout
