#!/usr/bin/python3
"""Live reload of a 1,000-rule spec by SIGHUP under 1 kHz violations: reload time, missed stops.

Live reload of a 1,000-rule spec with SIGHUP, while violations keep coming at 1 kHz:
the time each reload takes (the monitor's own figure, check included), and how many
violations went without a stop (must be none).
Target: under 1 s per reload, no missed violation. Usage: bench/reload.py [--reloads N] [--smoke]
"""
import argparse
import json
import os
import re
import signal
import sys
import tempfile
import threading
import time

import _common
from _rosbench import PrivateMaster, run_peer, spec_text, start_load, start_monitor, stop_processes


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reloads", type=_common.above_zero(int), default=10, help="SIGHUPs, 1.2 s apart (default 10)")
    ap.add_argument("--smoke", action="store_true", help="2 reloads of 101 rules, to check it works")
    args = ap.parse_args()
    reloads = 2 if args.smoke else args.reloads
    rules = 100 if args.smoke else 999
    with tempfile.TemporaryDirectory() as tmp:
        master = PrivateMaster(os.path.join(tmp, "home"))
        load = start_load(master, 20, 100)
        mon = None
        try:
            mon, path = start_monitor(master, tmp, spec_text(20, rules))
            seconds = reloads * 1.2 + 2.0
            result = {}
            driver = threading.Thread(target=lambda: result.update(
                run_peer(master, ["driver", "rubass", "1000", str(seconds)], seconds + 60)))
            driver.start()
            time.sleep(1.5)
            for i in range(reloads):
                with open(path) as fh:  # a changed rule each time, so that the swap has work to do
                    text = re.sub(r"> 1(0|1);", f"> 1{(i + 1) % 2};", fh.read(), count=1)
                with open(path, "w") as fh:
                    fh.write(text)
                os.kill(mon.pid, signal.SIGHUP)
                time.sleep(1.2)
            driver.join()
        finally:
            stop_processes(load + ([mon] if mon is not None else []))
            master.stop()
        log = open(os.path.join(tmp, "monitor.log")).read()
    times = [float(x) for x in re.findall(r"rubass: reloaded .* in (\d+) ms", log)]
    phases = re.findall(r"\(check (\d+) ms, build (\d+) ms, swap ([\d.]+) ms\)", log)
    swaps = [float(p[2]) for p in phases]
    checks = [float(p[0]) for p in phases]
    print(json.dumps({
        "benchmark": "reload", "rules": rules + 1, "reloads": len(times), "asked": reloads,
        "reload_ms_median": sorted(times)[len(times) // 2] if times else None,
        "reload_ms_max": max(times) if times else None,
        "check_ms_median": sorted(checks)[len(checks) // 2] if checks else None,
        "swap_ms_max": max(swaps) if swaps else None,
        "violations": result.get("expected"), "missed": result.get("unanswered"),
        "reaction_during_reloads_ms": {
            "p50": round(_common.percentile(result.get("latencies", []), 50) * 1e3, 3),
            "p99": round(_common.percentile(result.get("latencies", []), 99) * 1e3, 3),
            "max": round(max(result.get("latencies", [0])) * 1e3, 3)},
        "targets": {"under_1s": bool(times) and max(times) < 1000, "none_missed": result.get("unanswered") == 0},
        **_common.machine()}))


if __name__ == "__main__":
    sys.exit(main())
