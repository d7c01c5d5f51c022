#!/usr/bin/python3
"""Processes of bench/cpu.py, each its own node: `_cpu_peer.py ROLE ...`.

bare PROFILE            a bare rospy subscriber: one rospy.AnyMsg subscriber per topic of the
                        profile, counting; prints {"received": N} when stopped (SIGTERM/SIGINT)
pub PROFILE SCALE SECONDS WAIT [PART PARTS]
                        publish the profile's topics (those numbered PART modulo PARTS) at SCALE x
                        their rates, once WAIT subscribers are connected to every topic: prints
                        "ready", starts at a line "go" on stdin, and prints {"published": N,
                        "seconds": S} when done
"""
import json
import math
import signal
import sys
import threading
import time

import rospy

PROFILES = {
    # (a): 20 topics x 100 Hz, std_msgs/Float64
    "a": [(f"/bench/load_{i}", "float64", 100.0) for i in range(20)],
    # (b): a robot's sensors
    "b": [("/scan", "scan", 40.0), ("/imu", "imu", 200.0), ("/odom", "odom", 50.0),
          ("/joint_states", "joints", 100.0), ("/tf", "tf", 120.0)],
}


def profile(name):
    """`a`, `b`, or `aN` (N topics of profile a's kind, for the smoke test)."""
    if name in PROFILES:
        return PROFILES[name]
    return [(f"/bench/load_{i}", "float64", 100.0) for i in range(int(name[1:]))]


def messages(kind, k):
    """Two alternating messages of a kind (values that move, so rules change now and then)."""
    from geometry_msgs.msg import TransformStamped
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import Imu, JointState, LaserScan
    from std_msgs.msg import Float64

    if kind == "float64":
        return Float64(float(k % 7))
    if kind == "scan":
        m = LaserScan(angle_min=-2.35, angle_max=2.35, angle_increment=4.7 / 1080, range_min=0.05, range_max=30.0)
        # a real scan: some beams without a return (+inf), a few NaN
        m.ranges = [math.inf if (i * 7 + k) % 20 == 0 else (math.nan if i % 50 == 3 else 1.0 + ((i + k) % 300) / 100.0)
                    for i in range(1081)]
        m.intensities = [100.0] * 1081
        m.header.frame_id = "laser"
        return m
    if kind == "imu":
        m = Imu()
        m.header.frame_id = "imu"
        m.linear_acceleration.z = 9.81
        m.angular_velocity.z = 0.1 * (k % 5)
        m.orientation.w = 1.0
        return m
    if kind == "odom":
        m = Odometry()
        m.header.frame_id, m.child_frame_id = "odom", "base_link"
        m.twist.twist.linear.x = 0.1 * (k % 10)
        m.twist.twist.angular.z = 0.05 * (k % 7)
        m.pose.pose.position.x = 0.01 * k
        return m
    if kind == "joints":
        names = [f"joint_{i}" for i in range(12)]
        return JointState(name=names, position=[0.1 * (k % 9)] * 12, velocity=[0.2 * (k % 3)] * 12, effort=[1.0] * 12)
    if kind == "tf":
        tfs = []
        for child in ("base_link", "laser", "imu"):
            t = TransformStamped()
            t.header.frame_id, t.child_frame_id = "odom", child
            t.transform.rotation.w = 1.0
            t.transform.translation.x = 0.01 * k
            tfs.append(t)
        return _tf_class()(transforms=tfs)
    raise ValueError(kind)


def _tf_class():
    """tf2_msgs/TFMessage, built from its definition where tf2_msgs is not installed."""
    try:
        from tf2_msgs.msg import TFMessage
        return TFMessage
    except ImportError:
        import genpy.dynamic
        from geometry_msgs.msg import TransformStamped

        text = ("geometry_msgs/TransformStamped[] transforms\n" + "=" * 80 + "\nMSG: geometry_msgs/TransformStamped\n"
                + TransformStamped._full_text)
        return genpy.dynamic.generate_dynamic("tf2_msgs/TFMessage", text)["tf2_msgs/TFMessage"]


def _type_of(kind):
    return type(messages(kind, 0))


def bare(name):
    rospy.init_node("bench_bare")
    count = [0]

    def cb(msg):
        count[0] += 1

    subs = [rospy.Subscriber(topic, rospy.AnyMsg, cb, tcp_nodelay=True) for topic, _, _ in profile(name)]
    done = threading.Event()
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda *a: done.set())
    while not done.wait(0.2):
        pass
    print(json.dumps({"received": count[0]}), flush=True)
    for s in subs:
        s.unregister()


def pub(name, scale, seconds, wait, part=0, parts=1):
    rospy.init_node("bench_cpu_pub" if part == 0 else f"bench_cpu_pub_{part}")
    topics = [t for i, t in enumerate(profile(name)) if i % parts == part]
    pubs = [(rospy.Publisher(t, _type_of(kind), queue_size=100, tcp_nodelay=True), kind, hz * scale)
            for t, kind, hz in topics]
    samples = {kind: [messages(kind, k) for k in range(4)] for _, kind, _ in topics}
    end = time.monotonic() + 30
    while any(p.get_num_connections() < wait for p, _, _ in pubs) and time.monotonic() < end:
        time.sleep(0.05)
    time.sleep(1.0)  # every connection of every subscriber up
    print("ready", flush=True)
    sys.stdin.readline()  # "go": every publisher starts at once
    # one schedule of (due, publisher): each topic at its own rate, phases spread
    t0 = time.monotonic() + 0.05
    heap = [(t0 + i / (len(pubs) * hz), i) for i, (_, _, hz) in enumerate(pubs)]
    import heapq
    heapq.heapify(heap)
    n = 0
    stamp = rospy.Time.now
    stop = t0 + seconds
    while heap:
        due, i = heapq.heappop(heap)
        if due >= stop:
            continue
        delay = due - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        p, kind, hz = pubs[i]
        msg = samples[kind][n % 4]
        if hasattr(msg, "header"):
            msg.header.stamp = stamp()
        p.publish(msg)
        n += 1
        heapq.heappush(heap, (due + 1.0 / hz, i))
    elapsed = time.monotonic() - t0
    print(json.dumps({"published": n, "seconds": round(elapsed, 3)}), flush=True)
    time.sleep(0.5)  # let the last messages leave


if __name__ == "__main__":
    role = sys.argv[1]
    if role == "bare":
        bare(sys.argv[2])
    else:
        pub(sys.argv[2], float(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5]), *map(int, sys.argv[6:8]))
