#!/usr/bin/python3
"""Soak: the monitor for 10 minutes at 1,000 messages/s: missed stops, reaction, memory growth.

The monitor for --seconds (600) at 1,000 messages/s across 10 topics (100 Hz each),
with rules of the paper's shapes on every topic (Fig. 2's nested `for` over a command and an
encoder, speed limits with `for`, silence by `age`, rate by `frequency`), while a driver
alternates violation and clear at 20 Hz on the measured rule. Measured: violations without a
stop (must be none), reaction p50/p99, messages dropped, and the monitor's resident memory
from the end of the first tenth to the end (target: grows by less than 5 MB).
Usage: bench/soak.py [--seconds S] [--topics N] [--hz HZ] [--smoke]
"""
import argparse
import json
import os
import re
import tempfile
import threading
import time

import psutil

import _common
from _rosbench import PrivateMaster, run_peer, start_load, start_monitor, stop_processes


def soak_spec(topics):
    rules = ["  hit: topic /bench/cmd.point.x > 1;"]
    for i in range(topics):
        t, u = f"/bench/load_{i}", f"/bench/load_{(i + 1) % topics}"
        rules += [f"  erratic_{i}: ((topic {t}.data > 0.02 or topic {t}.data < -0.02) and topic {u}.data == 0) for 0.4 s;",
                  f"  erratic_long_{i}: erratic_{i} for 1 s;",
                  f"  fast_{i}: (abs(topic {t}.data) > 6.5) for 1 s;",
                  f"  silent_{i}: age(topic {t}) > 0.5 s;",
                  f"  slow_{i}: frequency(topic {t}) < 50 Hz;"]
    return ('import "lib.yaml";\naction primitive stop;\nentity bench { rules:\n' + "\n".join(rules) +
            "\n}\nif (bench.hit) then { stop; }\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=_common.above_zero(float), default=600.0, help="how long (default 600)")
    ap.add_argument("--topics", type=_common.above_zero(int), default=10, help="load topics (default 10)")
    ap.add_argument("--hz", type=_common.above_zero(float), default=100.0, help="messages per second on each topic")
    ap.add_argument("--smoke", action="store_true", help="5 s over 2 topics, to check it works")
    args = ap.parse_args()
    if args.smoke:
        args.seconds, args.topics = 5.0, 2
    with tempfile.TemporaryDirectory() as tmp:
        master = PrivateMaster(os.path.join(tmp, "home"))
        load, mon = start_load(master, args.topics, args.hz), None
        try:
            mon, _ = start_monitor(master, tmp, soak_spec(args.topics))
            proc = psutil.Process(mon.pid)
            result = {}
            driver = threading.Thread(target=lambda: result.update(
                run_peer(master, ["driver", "rubass", "20", str(args.seconds)], args.seconds + 120)))
            t0 = time.time()
            driver.start()
            samples = []  # (seconds since start, rss)
            while driver.is_alive():
                samples.append((time.time() - t0, proc.memory_info().rss))
                driver.join(min(5.0, args.seconds / 20))
            alive = mon.poll() is None
            stop_processes([mon])
        finally:
            stop_processes(load + [p for p in [mon] if p is not None])
            master.stop()
        log = open(os.path.join(tmp, "monitor.log")).read()
    m = re.search(r"stopped after (\d+) messages? \((\d+) dropped", log)
    warm = next(rss for t, rss in samples if t >= args.seconds / 10)
    lat = result.get("latencies", [])
    print(json.dumps({
        "benchmark": "soak", "seconds": args.seconds, "topics": args.topics, "messages_per_s": args.topics * args.hz,
        "rules": 1 + 5 * args.topics, "messages": int(m.group(1)) if m else None,
        "dropped": int(m.group(2)) if m else None,
        "violations": result.get("expected"), "missed": result.get("unanswered"),
        "reaction_ms_p50": round(_common.percentile(lat, 50) * 1e3, 3),
        "reaction_ms_p99": round(_common.percentile(lat, 99) * 1e3, 3),
        "reaction_ms_max": round(max(lat) * 1e3, 3) if lat else None,
        "rss_warm_mb": round(warm / 1e6, 2), "rss_end_mb": round(samples[-1][1] / 1e6, 2),
        "rss_growth_mb": round((samples[-1][1] - warm) / 1e6, 2), "monitor_alive": alive,
        **_common.machine()}))


if __name__ == "__main__":
    main()
