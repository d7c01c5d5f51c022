"""rospy gives every subscriber of a topic in one process the class of the first. The spec's topics
are subscribed as rospy.AnyMsg (bytes); a spec that names a topic rospy or the monitor itself
subscribes with a type shared it: an acceptance tester's spec guarding the agents with
`age(topic /rubass/agent_samples)` made every agent report a traceback (`'AnyMsg' object has no
attribute 'data'`) and the monitor heard no agent; `/clock` under use_sim_time, subscribed by rospy
as rosgraph_msgs/Clock, reached the spec's rules as a Clock object and never as bytes."""
import subprocess
import time

import pytest
from rosharness import PY, monitor_values, spec

pytestmark = [pytest.mark.ros, pytest.mark.slow]

AGENT = """import json, sys, time
import rospy
from std_msgs.msg import String
rospy.init_node("fake_agent")
pub = rospy.Publisher("/rubass/agent_samples", String, queue_size=10)
time.sleep(1.0)
for i in range(40):
    pub.publish(String(data=json.dumps({"agent": "/fake_agent", "host": "10.9.9.9", "period": 0.1, "time": 0,
                                        "nodes": []})))
    time.sleep(0.1)
print("done", flush=True)
"""


def test_a_spec_that_guards_the_agents_topic_still_hears_the_agents(ros, tmp_path):
    body = ("entity a { rules:\n  quiet: age(topic /rubass/agent_samples) > 1 s;\n}\n"
            "if (a.quiet) then { brake; }\n")
    mon = ros.monitor(spec(tmp_path, body))
    agent = ros.spawn([PY, "-c", AGENT], "fake_agent", stdout=subprocess.PIPE, text=True)
    time.sleep(2.5)  # reporting at 10 Hz
    values = monitor_values(ros)
    assert "/fake_agent" in values["agents"], (values, ros.log(mon))
    listen = ros.probe({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}],
                        "steps": [{"sleep": 0.5}]})
    assert not [r for r in listen if r["kind"] == "recv"], "the agent reports: age under 1 s, no brake"
    assert agent.stdout.readline().strip() == "done"
    late = ros.probe({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}], "steps": [{"sleep": 2.5}]})
    assert [r for r in late if r["kind"] == "recv" and r["msg"]["data"] is True], ros.log(mon)  # silent: the rule
    log = ros.log(mon)
    assert "bad callback" not in log and "Traceback" not in log, log


def test_a_spec_that_reads_clock_under_use_sim_time_reads_it(ros, tmp_path):
    subprocess.run(["rosparam", "set", "/use_sim_time", "true"], env=ros.env, check=True, timeout=20)
    body = "entity a { rules:\n  ticking: age(topic /clock) < 1 s;\n}\nif (a.ticking) then { brake; }\n"
    mon = ros.monitor(spec(tmp_path, body))
    rec = ros.probe({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}],
                     "advertise": [{"topic": "/clock", "type": "rosgraph_msgs/Clock"}],
                     "steps": [{"wait_subscribers": "/clock"}, {"wait_publishers": "/brake"}, {"sleep": 0.3}] + [
                         step for i in range(40) for step in (
                             {"publish": "/clock", "msg": {"clock": {"secs": 50 + i // 10, "nsecs": (i % 10) * 100000000}}},
                             {"sleep": 0.05})]})
    log = ros.log(mon)
    assert [r for r in rec if r["kind"] == "recv" and r["msg"]["data"] is True], log  # /clock's messages reached it
    assert "bad callback" not in log and "Traceback" not in log, log
