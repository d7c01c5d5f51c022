#!/usr/bin/python3
"""Added latency of the `limit` action, beside one raw rospy hop, measured in one run.

Three paths, fed in turn by one sender process and timed by one receiver process:
  raw:    sender -> receiver                                   (one raw rospy hop)
  relay:  sender -> a 10-line rospy relay node -> receiver     (for reference: two raw hops)
  limit:  sender -> the rubass monitor, `limit` active -> receiver (command in -> clamped command out)
Each command is a geometry_msgs/Twist whose unclamped axes carry its sequence number and send time
(angular.x, angular.y); linear.x = 1.0 comes out of the limit clamped to 0.2 (checked). The monitor
also runs its engine (the limit is switched on by a rule). Added latency = path p50 - raw p50;
target: added(limit) <= 1.5 x raw hop at p50. Prints one JSON object.
Usage: bench/limit_latency.py [--samples N] [--hz HZ] [--smoke]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
import warnings

import _common
from _rosbench import PY, PrivateMaster, stop_processes
from rubass_experiments.master import wait_for_service

HERE = os.path.abspath(__file__)
PATHS = {"raw": ("/bench/raw", "/bench/raw"), "relay": ("/bench/relay_in", "/bench/relay_out"),
         "limit": ("/bench/cmd", "/bench/out")}
LIB = ("actions:\n  crawl:\n    plugin: limit\n    input: /bench/cmd\n    topic: /bench/out\n"
       "    linear_x: [-0.1 m/s, 0.2 m/s]\n    timeout: 5 s\n")
SPEC = ('import "lib.yaml";\naction primitive crawl;\nentity bench { rules: on: topic /bench/on.data > 0; }\n'
        "if (bench.on) then { crawl; }\n")


def relay() -> None:
    import rospy
    from geometry_msgs.msg import Twist

    rospy.init_node("relay")
    warnings.simplefilter("ignore")
    pub = rospy.Publisher("/bench/relay_out", Twist, queue_size=None, tcp_nodelay=True)
    rospy.Subscriber("/bench/relay_in", Twist, pub.publish, tcp_nodelay=True)
    rospy.spin()


def receiver(samples: int) -> None:
    import threading

    import rospy
    from geometry_msgs.msg import Twist

    rospy.init_node("receiver")
    lat = {name: [] for name in PATHS}
    seen = {name: set() for name in PATHS}  # send stamps already received, per path
    wrong = []
    done = threading.Event()

    def got(msg, name):
        now = time.time()
        if msg.angular.x < 0:  # the end marker
            done.set()
            return
        if msg.angular.y == 0.0:  # the limit's own zero command (none had come yet): not a sample
            return
        if msg.angular.y in seen[name]:  # the limit repeating its latest command at its rate: not a sample
            return
        seen[name].add(msg.angular.y)
        lat[name].append(now - msg.angular.y)
        if name == "limit" and msg.linear.x != 0.2:
            wrong.append(msg.linear.x)

    for name, (_, out) in PATHS.items():
        rospy.Subscriber(out, Twist, got, callback_args=name, tcp_nodelay=True)
    print("ready", flush=True)
    done.wait(samples * 0.1 + 60)
    time.sleep(0.3)
    print(json.dumps({"lat": lat, "wrong": wrong[:5]}), flush=True)
    rospy.signal_shutdown("done")


def sender(samples: int, hz: float) -> None:
    import rospy
    from geometry_msgs.msg import Twist
    from std_msgs.msg import Float64

    rospy.init_node("sender")
    warnings.simplefilter("ignore")  # queue_size=None (synchronous publish) on purpose
    pubs = {name: rospy.Publisher(inp, Twist, queue_size=None, tcp_nodelay=True) for name, (inp, _) in PATHS.items()}
    on = rospy.Publisher("/bench/on", Float64, queue_size=10, tcp_nodelay=True)
    end = time.time() + 30
    while time.time() < end and (min(p.get_num_connections() for p in pubs.values()) < 1 or
                                 on.get_num_connections() < 1):
        time.sleep(0.05)
    time.sleep(1.0)
    on.publish(Float64(1.0))
    time.sleep(0.5)
    names = list(PATHS)
    t = time.monotonic()
    for i in range(samples * len(names)):
        msg = Twist()
        msg.linear.x, msg.angular.x = 1.0, float(i)
        msg.angular.y = time.time()
        pubs[names[i % len(names)]].publish(msg)
        t += 1.0 / hz
        time.sleep(max(0.0, t - time.monotonic()))
    end_marker = Twist()
    end_marker.angular.x = -1.0
    time.sleep(0.2)
    for p in pubs.values():
        p.publish(end_marker)
    time.sleep(0.2)


def summary(values):
    p = _common.percentile
    return {"n": len(values), "p50_ms": round(p(values, 50) * 1e3, 3), "p90_ms": round(p(values, 90) * 1e3, 3),
            "p99_ms": round(p(values, 99) * 1e3, 3)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=_common.above_zero(int), default=2000, help="commands per path")
    ap.add_argument("--hz", type=_common.above_zero(float), default=150.0,
                    help="commands per second, all paths together")
    ap.add_argument("--smoke", action="store_true", help="a short run (50 commands per path), to check it works")
    ap.add_argument("--role", choices=("relay", "receiver", "sender"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.smoke:
        args.samples = 50
    if args.role == "relay":
        return relay()
    if args.role == "receiver":
        return receiver(args.samples)
    if args.role == "sender":
        return sender(args.samples, args.hz)
    with tempfile.TemporaryDirectory() as tmp:
        with open(os.path.join(tmp, "lib.yaml"), "w") as fh:
            fh.write(LIB)
        spec = os.path.join(tmp, "bench.rbs")
        with open(spec, "w") as fh:
            fh.write(SPEC)
        master = PrivateMaster(os.path.join(tmp, "ros_home"))
        procs = []
        try:
            mon = master.spawn([PY, os.path.join(_common.ROOT, "scripts", "monitor"), "__name:=rubass",
                                f"_spec:={spec}"], log=os.path.join(tmp, "monitor.log"))
            procs.append(mon)
            wait_for_service("/rubass/reset", mon, master.uri, 60)
            procs.append(master.spawn([PY, HERE, "--role", "relay"]))
            rec = subprocess.Popen([PY, HERE, "--role", "receiver", "--samples", str(args.samples)], env=master.env,
                                   stdout=subprocess.PIPE, text=True, start_new_session=True)
            procs.append(rec)
            assert rec.stdout.readline().strip() == "ready"
            subprocess.run([PY, HERE, "--role", "sender", "--samples", str(args.samples), "--hz", str(args.hz)],
                           env=master.env, check=True, timeout=args.samples * 3 / args.hz + 120)
            out = json.loads(rec.stdout.readline())
            rec.wait(10)
        finally:
            stop_processes(procs)
            master.stop()
    res = {name: summary(v) for name, v in out["lat"].items()}
    raw = res["raw"]["p50_ms"]
    added = {name: round(res[name]["p50_ms"] - raw, 3) for name in ("relay", "limit")}
    ratio = round(added["limit"] / raw, 2) if raw > 0 else None
    print(json.dumps({"benchmark": "limit_latency", "samples_per_path": args.samples, "hz": args.hz, "paths": res,
                      "added_p50_ms": added, "limit_added_over_raw_hop_p50": ratio,
                      "target": "limit added <= 1.5 x raw hop at p50", "met": ratio is not None and ratio <= 1.5,
                      "clamped_wrong": out["wrong"], "lost": {n: args.samples - res[n]["n"] for n in res},
                      **_common.machine()}))


if __name__ == "__main__":
    sys.exit(main())
