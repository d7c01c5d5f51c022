#!/usr/bin/python3
"""A reload storm (100 SIGHUPs in 10 s) under violations: missed stops, memory and threads.

--sighups SIGHUPs in --seconds s (100 in 10 s) while violations keep coming
at --hz, each SIGHUP after a rewrite of the spec; one rewrite in the middle is broken and must
change nothing. Measured: violations without a stop (must be none), reloads done, rejected and
coalesced, and the monitor's resident memory and threads before and after (no leak).
Usage: bench/reload_storm.py [--sighups N] [--seconds S] [--hz HZ] [--rules R] [--smoke]
"""
import argparse
import json
import os
import re
import signal
import tempfile
import threading
import time

import psutil

import _common
from _rosbench import PrivateMaster, run_peer, spec_text, start_monitor, stop_processes


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sighups", type=_common.above_zero(int), default=100, help="SIGHUPs sent (default 100)")
    ap.add_argument("--seconds", type=_common.above_zero(float), default=10.0,
                    help="over how many seconds (default 10)")
    ap.add_argument("--hz", type=_common.above_zero(float), default=50.0,
                    help="violation/clear alternations per second")
    ap.add_argument("--rules", type=_common.above_zero(int, zero_ok=True), default=100,
                    help="rules besides the measured one")
    ap.add_argument("--smoke", action="store_true", help="10 SIGHUPs in 2 s over 20 rules, to check it works")
    args = ap.parse_args()
    if args.smoke:
        args.sighups, args.seconds, args.rules = 10, 2.0, 20
    with tempfile.TemporaryDirectory() as tmp:
        master = PrivateMaster(os.path.join(tmp, "home"))
        mon = None
        try:
            good = spec_text(5, args.rules)
            mon, path = start_monitor(master, tmp, good)
            proc = psutil.Process(mon.pid)
            result = {}
            seconds = args.seconds + 2.0
            driver = threading.Thread(target=lambda: result.update(
                run_peer(master, ["driver", "rubass", str(args.hz), str(seconds)], seconds + 60)))
            driver.start()
            time.sleep(1.0)
            warm = []
            gap = args.seconds / args.sighups
            broken_at = args.sighups // 2
            for i in range(args.sighups):
                if i == broken_at:
                    text = good.replace("> 1;", "> ;", 1)  # a syntax error in the measured rule
                else:  # a changed load rule each time, so that every reload has work to do
                    text = re.sub(r"> 1(0|1);", f"> 1{i % 2};", good, count=1)
                with open(path, "w") as fh:
                    fh.write(text)
                os.kill(mon.pid, signal.SIGHUP)
                if i == args.sighups // 10:
                    warm = [proc.memory_info().rss, proc.num_threads()]
                # around the broken rewrite, long enough for each reload to be read on its own: the reload
                # before it must not read the broken file too (one broken spec counted as two rejections)
                time.sleep(gap if i not in (broken_at - 1, broken_at) else max(gap, 0.5))
            driver.join()
            time.sleep(1.0)  # the last reloads settle
            after = [proc.memory_info().rss, proc.num_threads()]
            alive = mon.poll() is None
            stop_processes([mon])
        finally:
            stop_processes([p for p in [mon] if p is not None])
            master.stop()
        log = open(os.path.join(tmp, "monitor.log")).read()
    print(json.dumps({
        "benchmark": "reload_storm", "sighups": args.sighups, "seconds": args.seconds, "rules": args.rules + 1,
        "reloads": len(re.findall(r"rubass: reloaded", log)), "rejected": len(re.findall(r"reload \(SIGHUP\) rejected", log)),
        "violations": result.get("expected"), "missed": result.get("unanswered"),
        "reaction_ms_p99": round(_common.percentile(result.get("latencies", []), 99) * 1e3, 3),
        "rss_growth_mb": round((after[0] - warm[0]) / 1e6, 2), "threads_before": warm[1], "threads_after": after[1],
        "monitor_alive": alive, **_common.machine()}))


if __name__ == "__main__":
    main()
