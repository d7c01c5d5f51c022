"""A reload that names a new topic while the master is down: rospy retries that registration
until the master is back, and holds its topic manager's lock meanwhile. The monitor makes it in
the background (rubass/ros/topics.py): the rules of the topics already connected go on being
enforced at once, and the heartbeat goes on (acceptance: the stop came 10.2 s late, after the
master returned, and the heartbeat paused 11.65 s)."""
import json
import os
import signal

import pytest

from rosharness import TWIST, first, records, spec, wait_log

pytestmark = [pytest.mark.ros, pytest.mark.slow]

FAST = "entity base { rules: fast: topic /cmd_vel.linear.x > 1.0 m/s; }\nif (base.fast) then { stop; }\n"
NEW = "entity newr { rules: newr2: topic /newtopic2.data > 1; }\nif (newr.newr2) then { brake; }\n"


def test_a_reload_adding_a_topic_while_the_master_is_down_stops_nothing_from_being_enforced(ros, tmp_path):
    path = spec(tmp_path, FAST)
    mon = ros.monitor(path, diagnostics_rate=5)  # a status every 0.2 s: each asks for the data errors
    driver = ros.probe_bg({"listen": [{"topic": "/safety_cmd", "type": TWIST},
                                      {"topic": "/rubass/heartbeat", "type": "std_msgs/Header"}],
                           "advertise": [{"topic": "/cmd_vel", "type": TWIST}],
                           "steps": [{"wait_subscribers": "/cmd_vel"}, {"wait_publishers": "/safety_cmd"},
                                     {"wait": "/rubass/heartbeat"}, {"sleep": 0.3}, {"mark": "ready"},
                                     {"sleep": 4.0}, {"mark": "violate"},
                                     {"publish": "/cmd_vel", "msg": {"linear": {"x": 2.0}}},
                                     {"wait": "/safety_cmd", "timeout": 15}, {"sleep": 0.5}]}, name="driver")
    early = []
    while not early or '"ready"' not in early[-1]:
        early.append(driver.stdout.readline())
        assert early[-1], "".join(early) + ros.log(driver)
    ros.master.stop()  # down: the driver's connections to the monitor are peer to peer and stay
    with open(path, "a") as fh:
        fh.write(NEW)
    os.kill(mon.pid, signal.SIGHUP)
    rec = [json.loads(line) for line in early] + records(driver)
    ready = next(r["wall"] for r in rec if r.get("name") == "ready")
    sent, stop = first(rec, "sent", "/cmd_vel"), first(rec, "recv", "/safety_cmd")
    assert stop is not None, ros.log(mon)
    assert stop["wall"] - sent["wall"] < 0.1, (stop["wall"] - sent["wall"], ros.log(mon))
    beats = [r["wall"] for r in rec if r["kind"] == "recv" and r["topic"] == "/rubass/heartbeat"
             and ready <= r["wall"] <= stop["wall"]]
    gaps = [b - a for a, b in zip(beats, beats[1:])]
    assert len(beats) > 50 and max(gaps) < 0.5, (len(beats), max(gaps, default=None))  # 50 Hz ticks
    wait_log(mon, ros, "reloaded", timeout=0.5)  # long ago: the reload does not wait for the master
    log = ros.log(mon)
    assert "topic /newtopic2: the master does not answer" in log
    assert "STATUS UNAVAILABLE" not in log and mon.poll() is None

    # the master back: the new topic is subscribed and its rule enforced
    ros.master.restart()
    wait_log(mon, ros, "topic /newtopic2: subscribed after", timeout=5)
    rec = ros.probe({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}],
                     "advertise": [{"topic": "/newtopic2", "type": "std_msgs/Float64"}],
                     "steps": [{"wait_subscribers": "/newtopic2", "timeout": 5}, {"wait_publishers": "/brake"},
                               {"sleep": 0.3}, {"publish": "/newtopic2", "msg": {"data": 2.0}},
                               {"wait": "/brake", "timeout": 3}]})
    sent, brake = first(rec, "sent", "/newtopic2"), first(rec, "recv", "/brake")
    assert brake is not None and brake["wall"] - sent["wall"] < 0.1, ros.log(mon)
    assert mon.poll() is None


def test_sigterm_exits_while_a_subscription_waits_for_the_master(ros, tmp_path):
    """Re-sweep finding: after such a reload, SIGTERM logged "stopped" but the process stayed (25 s,
    then SIGKILL): rospy's shutdown waited for the registration that retries the absent master.
    The monitor releases its actions, then exits 0 within a few seconds whatever rospy waits for."""
    import time

    import rosgraph

    path = spec(tmp_path, FAST)
    mon = ros.monitor(path)
    master = rosgraph.Master("/t", master_uri=ros.env["ROS_MASTER_URI"])
    end = time.monotonic() + 10
    while time.monotonic() < end and not any(t == "/cmd_vel" and "/rubass" in who
                                             for t, who in master.getSystemState()[1]):
        time.sleep(0.05)  # its first subscription made: only the reload's new one waits for the master
    ros.master.stop()
    with open(path, "a") as fh:
        fh.write(NEW)
    os.kill(mon.pid, signal.SIGHUP)
    wait_log(mon, ros, "topic /newtopic2: the master does not answer", timeout=10)
    t0 = time.monotonic()
    mon.send_signal(signal.SIGTERM)
    try:
        status = mon.wait(15)
    except Exception:
        raise AssertionError(ros.log(mon))
    assert status == 0, ros.log(mon)
    assert time.monotonic() - t0 < 12, time.monotonic() - t0  # 5 s + 1 s per action (3), at most
    assert "stopped after" in ros.log(mon)


def test_a_reload_adding_a_publish_action_while_the_master_is_down_says_it_waits(ros, tmp_path):
    """Re-sweep finding: such a reload waited for the master (its new publisher registers with it)
    without a word: the new rule was silently not enforced. It says so now; the old rules go on."""
    from rosharness import LIB

    path = spec(tmp_path, FAST)
    mon = ros.monitor(path)
    ros.master.stop()
    (tmp_path / "lib.yaml").write_text(LIB + "  horn: {plugin: publish, topic: /horn, type: std_msgs/Bool, "
                                              "message: {data: true}, rate: 5 Hz}\n")
    with open(path, "a") as fh:
        fh.write("action primitive horn;\nentity h { rules: loud: topic /cmd_vel.angular.z > 1; }\n"
                 "if (h.loud) then { horn; }\n")
    os.kill(mon.pid, signal.SIGHUP)
    wait_log(mon, ros, "setting up its new actions waits for the master", timeout=10)
    assert "reloaded" not in ros.log(mon) and mon.poll() is None
    ros.master.restart()
    wait_log(mon, ros, "reloaded", timeout=20)
