#!/usr/bin/python3
"""Replay throughput: `rubass replay --json` over a generated bag of small messages.

Target (issue 17): >= 100,000 messages/s on 1,000,000 messages. The bag (std_msgs/Float64 on
4 topics at 1 kHz each, read by 8 rules) is written once into --dir and reused.
The child's CPU time is reported too (cpu_s): on a shared machine it varies less than the wall clock.
Usage: bench/replay_throughput.py [--messages N] [--dir DIR]
"""
import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

import _common  # noqa: F401

SPEC = """import "{lib}";
action primitive stop, warn;
entity w {{ rules:
  l_fast: (abs(topic /wheel_left/encoder.data) > 0.8 m/s) for 0.5 s;
  r_fast: (abs(topic /wheel_right/encoder.data) > 0.8 m/s) for 0.5 s;
  l_cmd: abs(topic /wheel_left/cmd.data) > 0.05 m/s;
  r_cmd: abs(topic /wheel_right/cmd.data) > 0.05 m/s;
  l_dead: (l_cmd and abs(topic /wheel_left/encoder.data) < 0.02 m/s) for 0.4 s;
  r_dead: (r_cmd and abs(topic /wheel_right/encoder.data) < 0.02 m/s) for 0.4 s;
  silent: age(topic /wheel_left/encoder) > 0.5 s or age(topic /wheel_right/encoder) > 0.5 s;
  slow_cmd: frequency(topic /wheel_left/cmd) < 500 Hz;
}}
if (w.l_fast or w.r_fast) then {{ stop; }}
if ((w.l_dead for 1 s) or (w.r_dead for 1 s)) then {{ stop; }}
if (w.silent or w.slow_cmd) then {{ warn; }}
"""
TARGET = 100000  # messages/s (issue 17)
TOPICS = ["/wheel_left/cmd", "/wheel_right/cmd", "/wheel_left/encoder", "/wheel_right/encoder"]


def make_bag(path, n):
    import math

    import rosbag
    import rospy
    from std_msgs.msg import Float64

    with rosbag.Bag(path, "w") as bag:
        for i in range(n):
            t = 1700000000.0 + (i // len(TOPICS)) * 0.001
            topic = TOPICS[i % len(TOPICS)]
            bag.write(topic, Float64(0.5 + 0.45 * math.sin(t / 3.0)), rospy.Time.from_sec(t))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--messages", type=_common.above_zero(int), default=1000000,
                    help="messages in the generated bag (default 1000000)")
    ap.add_argument("--dir", default=os.path.join(tempfile.gettempdir(), "rubass-bench"),
                    help="where the bag is generated (and kept for the next run)")
    args = ap.parse_args()
    os.makedirs(args.dir, exist_ok=True)
    bag = os.path.join(args.dir, f"replay_{args.messages}.bag")
    write_s = None
    if not os.path.exists(bag):
        t0 = time.perf_counter()
        make_bag(bag + ".tmp", args.messages)
        os.replace(bag + ".tmp", bag)
        write_s = time.perf_counter() - t0
    spec = os.path.join(args.dir, "replay.rbs")
    with open(spec, "w") as fh:
        fh.write(SPEC.format(lib=_common.LIB))
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "rubass", "replay", spec, bag, "--json"], cwd=_common.ROOT,
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    elapsed = time.perf_counter() - t0
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (cpu1.ru_utime - cpu0.ru_utime) + (cpu1.ru_stime - cpu0.ru_stime)
    if proc.returncode != 0:
        sys.exit(proc.stderr)
    print(json.dumps({
        "benchmark": "replay_throughput", "messages": args.messages, "seconds": round(elapsed, 3),
        "messages_per_s": round(args.messages / elapsed), "cpu_s": round(cpu, 3),
        "messages_per_cpu_s": round(args.messages / cpu) if cpu else None, "events": len(proc.stdout.splitlines()),
        "bag_write_s": None if write_s is None else round(write_s, 2),
        "target_messages_per_s": TARGET, "met": args.messages / elapsed >= TARGET, **_common.machine(),
    }))


if __name__ == "__main__":
    main()
