#!/usr/bin/python3
"""Floods a topic for the fault tests, then sends one violation and times the monitor's stop.

    flood.py burst N        N std_msgs/Float64 on /x (data 0 and 0.5 in turn) as fast as rospy publishes them
    flood.py huge N SIZE    N std_msgs/Float64MultiArray on /cloud of SIZE float64 each, 10 per s

then one violation (/x data 5, or a /cloud whose max is 9) and a wait for /safety_cmd.
Prints one JSON line: {"sent": …, "seconds": …, "stop_after_s": … or null}.
"""
import json
import sys
import threading
import time

import rospy
from geometry_msgs.msg import Twist
from std_msgs.msg import Float64, Float64MultiArray


def main():
    mode, n = sys.argv[1], int(sys.argv[2])
    rospy.init_node("flood", anonymous=True, disable_signals=True)
    stopped = threading.Event()
    rospy.Subscriber("/safety_cmd", Twist, lambda m: stopped.set(), tcp_nodelay=True)
    topic, cls = ("/x", Float64) if mode == "burst" else ("/cloud", Float64MultiArray)
    pub = rospy.Publisher(topic, cls, queue_size=n + 1, tcp_nodelay=True)
    end = time.time() + 10
    while (pub.get_num_connections() < 1 or "/safety_cmd" not in dict(rospy.get_published_topics())) \
            and time.time() < end:
        time.sleep(0.05)
    time.sleep(0.5)
    t0 = time.time()
    if mode == "burst":
        msgs = (Float64(0.0), Float64(0.5))  # harmless values that change: every rule reading /x is evaluated
        for i in range(n):
            pub.publish(msgs[i % 2])
        violation = Float64(5.0)
    else:
        size = int(sys.argv[3])
        msg = Float64MultiArray(data=[1.0] * size)
        for _ in range(n):
            pub.publish(msg)
            time.sleep(0.1)
        violation = Float64MultiArray(data=[1.0] * (size - 1) + [9.0])
    seconds = time.time() - t0
    time.sleep(0.2)
    sent = time.time()
    pub.publish(violation)
    got = stopped.wait(20)
    print(json.dumps({"sent": n, "seconds": seconds, "stop_after_s": time.time() - sent if got else None}))
    rospy.signal_shutdown("done")


if __name__ == "__main__":
    main()
