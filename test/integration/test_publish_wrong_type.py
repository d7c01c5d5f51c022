"""A stop published with a type its topic's subscribers do not take reaches no one (rospy refuses the
connection); the failure says so, naming the node and the type it takes, not "no node subscribes",
which sent the engineer looking for a dead base (found by an acceptance sweep)."""
import re

import pytest

from rosharness import brake_after, spec, wait_log

pytestmark = pytest.mark.ros

LIB = """actions:
  stop: {plugin: publish, topic: /safety_cmd, type: geometry_msgs/TwistStamped, message: {}, rate: 20 Hz}
  brake: {plugin: publish, topic: /brake, type: std_msgs/Bool, message: {data: true}, rate: 20 Hz}
  warn: {plugin: log, level: warn}
"""


def test_a_stop_whose_subscribers_take_another_type_says_which_node_and_type(ros, tmp_path):
    base = ros.probe_bg({"listen": [{"topic": "/safety_cmd", "type": "geometry_msgs/Twist"}],
                         "steps": [{"mark": "ready"}, {"sleep": 20}]}, name="base")
    assert '"ready"' in base.stdout.readline(), ros.log(base)
    mon = ros.monitor(spec(tmp_path, "entity e { rules: fast: topic /cmd_vel.linear.x > 3 m/s; }\n"
                                     "if (e.fast) then { stop; brake; }\n", lib=LIB))
    assert brake_after(ros, 4.0)  # the behaviour is on: its stop cannot reach the base
    wait_log(mon, ros, "/safety_cmd has subscribers of another type (")
    log = ros.log(mon)
    assert re.search(r"\(/probe_\w+ as geometry_msgs/Twist; this action publishes geometry_msgs/TwistStamped, and "
                     r"rospy refuses a connection whose type differs\): the message reached no one", log), log
    assert "no node subscribes to /safety_cmd" not in log
