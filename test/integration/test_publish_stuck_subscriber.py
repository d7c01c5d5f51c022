"""A subscriber that stops reading (a node stopped, its link cut) must not hold the stop from the
others (an acceptance tester's finding: with the stop written synchronously, the base stopped
receiving it 35 s after a recorder's link was cut, once that recorder's socket buffers were full,
while ~heartbeat went on). The stop's publisher now writes each subscriber from a thread of its
own; here the stuck one is SIGSTOPped and the stop is large, so its buffers fill in a second."""
import json
import os
import signal
import subprocess
import time

import pytest
from rosharness import PY, TWIST, spec

pytestmark = [pytest.mark.ros, pytest.mark.slow]

BIG = "x" * 400_000  # bytes a stop: 8 MB/s at 20 Hz
LIB = ("actions:\n"
       f"  stop: {{plugin: publish, topic: /stop_big, type: std_msgs/String, message: {{data: {BIG}}}, rate: 20 Hz}}\n"
       "  brake: {plugin: publish, topic: /brake, type: std_msgs/Bool, message: {data: true}, rate: 20 Hz}\n"
       "  warn: {plugin: log, level: warn}\n")
BODY = "entity a { rules:\n  fast: topic /cmd_vel.linear.x > 1;\n}\nif (a.fast) then { stop; }\n"

LISTENER = """
import json, sys, time
import rospy
from std_msgs.msg import String
rospy.init_node(sys.argv[1])
got = []
rospy.Subscriber("/stop_big", String, lambda m: got.append(time.time()), tcp_nodelay=True)
print("ready", flush=True)
end = time.time() + float(sys.argv[2])
while time.time() < end:
    time.sleep(0.05)
print(json.dumps(got), flush=True)
"""


def test_a_subscriber_that_stops_reading_does_not_hold_the_stop_from_the_base(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, BODY, lib=LIB))
    stuck = ros.spawn([PY, "-c", LISTENER, "recorder", "60"], "recorder", stdout=subprocess.PIPE, text=True)
    base = ros.spawn([PY, "-c", LISTENER, "base", "12"], "base", stdout=subprocess.PIPE, text=True)
    assert stuck.stdout.readline().strip() == "ready" and base.stdout.readline().strip() == "ready"
    try:
        ros.probe({"advertise": [{"topic": "/cmd_vel", "type": TWIST}],
                   "steps": [{"wait_subscribers": "/cmd_vel"}, {"sleep": 1.5},
                             {"publish": "/cmd_vel", "msg": {"linear": {"x": 2.0}}}, {"sleep": 1.0}]})
        os.kill(stuck.pid, signal.SIGSTOP)  # stops reading: its buffers fill within a second
        cut = time.time()
        out, _ = base.communicate(timeout=30)
    finally:
        os.kill(stuck.pid, signal.SIGCONT)
    got = json.loads(out.strip().splitlines()[-1])
    after = [t for t in got if t > cut + 3.0]  # from 3 s after the cut to the end of the base's 12 s
    assert got and after, (len(got), ros.log(mon))
    gaps = [b - a for a, b in zip(after, after[1:])]
    assert len(after) >= 20 * 3 and max(gaps) < 0.5, (len(after), max(gaps, default=None), ros.log(mon))
