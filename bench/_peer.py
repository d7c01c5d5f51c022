#!/usr/bin/python3
"""ROS processes for the benchmarks: `_peer.py ROLE [args]`, each its own node.

echo            republish /bench/raw on /bench/raw_back at once (the raw rospy hop, twice)
load N HZ [FIRST]  publish N topics /bench/load_I (I from FIRST; std_msgs/Float64) at HZ each
timed T COUNT   one violation then silence, COUNT times, against a rule `for T s`
driver MODE HZ SECONDS   measure, printing one JSON line:
    raw:    publish a stamped Header on /bench/raw at HZ; round trip via echo -> one hop = rtt/2
    rubass: alternate /bench/cmd (geometry_msgs/PointStamped) between violating (x=2) and clear
            (x=0) at HZ; the k-th stop on /bench/stop (std_msgs/Header) answers the k-th violation

Every publisher on a measured path (echo, driver, timed) publishes synchronously
(`queue_size=None`), as the monitor's publish action does, so the raw hop and rubass's path pay
the same publish; only the background load goes through rospy's queue thread.
"""
import json
import sys
import threading
import time
import warnings

import rospy
from geometry_msgs.msg import PointStamped
from std_msgs.msg import Float64, Header


def _sync_publisher(topic, cls):
    """A synchronous publisher (publish() writes on the caller's thread), rospy's warning about
    queue_size=None silenced: it is on purpose."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rospy.Publisher(topic, cls, queue_size=None, tcp_nodelay=True)


def echo():
    rospy.init_node("bench_echo")
    pub = _sync_publisher("/bench/raw_back", Header)
    rospy.Subscriber("/bench/raw", Header, pub.publish, tcp_nodelay=True)
    rospy.spin()


def load(n, hz, first=0):
    rospy.init_node("bench_load", anonymous=True)
    pubs = [rospy.Publisher(f"/bench/load_{i}", Float64, queue_size=10, tcp_nodelay=True) for i in range(first, first + n)]
    rate = rospy.Rate(hz)
    k = 0
    while not rospy.is_shutdown():
        k += 1
        for p in pubs:
            p.publish(Float64(k % 7))
        try:
            rate.sleep()
        except rospy.ROSInterruptException:
            break


def driver(mode, hz, seconds):
    rospy.init_node("bench_driver")
    lat = []
    lock = threading.Lock()
    sent = {}
    if mode == "raw":
        pub = _sync_publisher("/bench/raw", Header)

        def back(msg):
            now = time.time()
            with lock:
                t = sent.pop(msg.seq, None)
            if t is not None:
                lat.append((now - t) / 2.0)

        rospy.Subscriber("/bench/raw_back", Header, back, tcp_nodelay=True)
        wait_for = "/bench/raw_back"
    else:
        pub = _sync_publisher("/bench/cmd", PointStamped)
        violations = []  # send times; the k-th stop answers the k-th violation (one stop per start)
        stops = []

        def stop(msg):
            stops.append(time.time())

        rospy.Subscriber("/bench/stop", Header, stop, tcp_nodelay=True)
        wait_for = "/bench/stop"
    end = time.time() + 15
    while pub.get_num_connections() < 1 and time.time() < end:
        time.sleep(0.01)
    while wait_for not in dict(rospy.get_published_topics()) and time.time() < end:
        time.sleep(0.05)
    time.sleep(0.5)
    period = 1.0 / hz
    n = int(seconds * hz)
    t_next = time.time()
    for i in range(n):
        t_next += period
        if mode == "raw":
            with lock:
                sent[i] = time.time()
            pub.publish(Header(seq=i))
        else:
            msg = PointStamped()
            violate = i % 2 == 0
            msg.point.x = 2.0 if violate else 0.0
            if violate:
                violations.append(time.time())
            pub.publish(msg)
        delay = t_next - time.time()
        if delay > 0:
            time.sleep(delay)
    time.sleep(0.5)
    if mode != "raw":
        # late is not missed: wait until every violation is answered, or none has been for 3 s
        last, seen = time.time(), len(stops)
        while len(stops) < len(violations) and time.time() - last < 3.0:
            time.sleep(0.05)
            if len(stops) != seen:
                last, seen = time.time(), len(stops)
        lat = [s - v for v, s in zip(violations, stops)]
        print(json.dumps({"latencies": lat, "expected": len(violations), "unanswered": len(violations) - len(stops),
                          "extra_stops": max(0, len(stops) - len(violations))}))
        return
    print(json.dumps({"latencies": lat, "expected": n, "unanswered": n - len(lat)}))


def timed(duration, count):
    """One violation, then silence: the stop's arrival minus (t0 + T); and the monitor's own
    error from its ~events (dispatch minus the deadline)."""
    from std_msgs.msg import String

    rospy.init_node("bench_timed")
    pub = _sync_publisher("/bench/cmd", PointStamped)
    got = threading.Event()
    arrival = {}
    own = []

    def stop(msg):
        if not got.is_set():
            arrival["t"] = time.time()
            got.set()

    def event(msg):
        e = json.loads(msg.data)
        if e["event"] == "start" and e["cause"] == "deadline" and e["latency_ms"] is not None:
            own.append(e["latency_ms"] / 1000.0)

    rospy.Subscriber("/bench/stop", Header, stop, tcp_nodelay=True)
    rospy.Subscriber("/rubass/events", String, event, tcp_nodelay=True)
    end = time.time() + 15
    while (pub.get_num_connections() < 1 or "/bench/stop" not in dict(rospy.get_published_topics())) \
            and time.time() < end:
        time.sleep(0.05)
    time.sleep(0.5)
    errors = []
    # one warm-up firing, not counted: the first message of a topic's type costs the monitor a
    # one-off type lookup and field check (a few ms), which a running robot has long paid
    for i in range(count + 1):
        if i == 1:
            own.clear()
        got.clear()
        msg = PointStamped()
        msg.point.x = 2.0
        t0 = time.time()
        pub.publish(msg)
        if got.wait(duration + 2.0) and i > 0:
            errors.append(arrival["t"] - t0 - duration)
        msg.point.x = 0.0
        pub.publish(msg)
        time.sleep(0.15)
    time.sleep(0.2)
    print(json.dumps({"errors": errors, "monitor_errors": own, "expected": count}))


if __name__ == "__main__":
    role = sys.argv[1]
    if role == "echo":
        echo()
    elif role == "load":
        load(int(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4]) if len(sys.argv) > 4 else 0)
    elif role == "timed":
        timed(float(sys.argv[2]), int(sys.argv[3]))
    else:
        driver(sys.argv[2], float(sys.argv[3]), float(sys.argv[4]))
