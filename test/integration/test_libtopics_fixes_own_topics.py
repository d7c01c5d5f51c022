"""An action may not publish on the monitor's own topics (libtopics.MONITOR_TOPICS): at start a
name that is the monitor's own only under its real node name is refused, and a reload adding one
is rejected while the heartbeat goes on unforged (acceptance: a String on ~heartbeat reached a
Header subscriber as a heartbeat stamped 2027, fed to the hardware watchdog)."""
import time

import pytest
import yaml
from rosharness import wait_log

pytestmark = [pytest.mark.ros, pytest.mark.slow]

LIB = "actions:\n  stop: {plugin: publish, topic: /safe, type: geometry_msgs/Twist, message: {}, rate: 20 Hz}\n"
HBX = '  hbx: {plugin: publish, topic: ~heartbeat, type: std_msgs/String, message: {data: "2027 is late"}}\n'
SPEC = ('import "lib.yaml";\naction primitive stop;\n'
        "entity e { rules: far: topic /far.data > 1; }\nif (e.far) then { stop; }\n")


def beats(ros, topic, seconds=1.0):
    rec = ros.probe({"listen": [{"topic": topic, "type": "std_msgs/Header"}], "steps": [{"sleep": seconds}]})
    return [r["msg"] for r in rec if r["kind"] == "recv"]


def test_a_reload_adding_an_action_on_the_heartbeat_is_rejected_and_the_heartbeat_stays_true(ros, tmp_path):
    (tmp_path / "lib.yaml").write_text(LIB)
    (tmp_path / "s.rbs").write_text(SPEC)
    mon = ros.monitor(str(tmp_path / "s.rbs"), name="safety")
    assert beats(ros, "/safety/heartbeat"), ros.log(mon)
    (tmp_path / "lib.yaml").write_text(LIB + HBX)
    time.sleep(0.1)
    out = ros.call("/safety/reload")
    answer = yaml.safe_load(out.stdout)
    assert answer["success"] is False, out.stdout
    assert "lib.yaml:3:33: error: action 'hbx': publishes std_msgs/String on ~heartbeat, the monitor's own " \
           "topic: its heartbeat" in answer["message"], answer["message"]
    got = beats(ros, "/safety/heartbeat")
    assert got and all(b["frame_id"] == "rubass" and abs(b["stamp"]["secs"] - time.time()) < 60 for b in got), got[:3]


def test_at_start_a_name_that_is_the_monitors_own_under_its_node_name_is_refused(ros, tmp_path):
    """`rubass check` resolves as for a monitor named /rubass; the monitor named /safety resolves
    `/safety/events` as its own ~events and does not enforce the spec."""
    lib = LIB + "  ev: {plugin: publish, topic: /safety/events, type: std_msgs/Header}\n"
    (tmp_path / "lib.yaml").write_text(lib)
    (tmp_path / "s.rbs").write_text(SPEC)
    mon = ros.monitor(str(tmp_path / "s.rbs"), name="safety")
    wait_log(mon, ros, "NOT ENFORCING ANY RULE")
    log = ros.log(mon)
    assert "lib.yaml:3:32: error: action 'ev': publishes std_msgs/Header on /safety/events, the monitor's own " \
           "topic (~events)" in log, log
    assert not beats(ros, "/safety/heartbeat", 0.5), "not enforcing: no heartbeat"
