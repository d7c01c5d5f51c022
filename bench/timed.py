#!/usr/bin/python3
"""How late a `for` fires through the live monitor, after one violating message then silence.

One violating message then silence, for T
from 0 to 2 s. The monitor's own error (its ~events: the instant it dispatched the stop minus
t0 + T, t0 being the violating message's arrival) is what the target is about; the stop's
arrival at a subscriber minus (send time + T) adds the two ROS hops and is printed too.
Target: p99 <= 1 ms. Each T starts with one warm-up firing. Usage: bench/timed.py [--count N] [--smoke]
"""
import argparse
import json
import os
import sys
import tempfile

import _common
from _rosbench import PrivateMaster, run_peer, spec_text, start_monitor, stop_processes


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=_common.above_zero(int), default=30,
                    help="firings per T of 0.5 s or less; a third of it, at least 5, for 1 and 2 s (default 30)")
    ap.add_argument("--smoke", action="store_true", help="2 firings of one T (0.1 s), to check it works")
    args = ap.parse_args()
    durations = [0.1] if args.smoke else [0.0, 0.05, 0.1, 0.5, 1.0, 2.0]
    all_errors, all_own = [], []
    with tempfile.TemporaryDirectory() as tmp:
        master = PrivateMaster(os.path.join(tmp, "home"))
        try:
            for T in durations:
                count = 2 if args.smoke else (args.count if T <= 0.5 else max(5, args.count // 3))
                mon, _ = start_monitor(master, tmp, spec_text(1, 0, f"(topic /bench/cmd.point.x > 1) for {T} s"))
                try:
                    r = run_peer(master, ["timed", str(T), str(count)], count * (T + 3) + 60)
                finally:
                    stop_processes([mon])
                errs, own = r["errors"], r["monitor_errors"]
                all_errors += errs
                all_own += own
                p = _common.percentile
                print(json.dumps({
                    "benchmark": "timed", "T_s": T, "firings": len(errs), "missed": r["expected"] - len(errs),
                    "at_subscriber_ms": {"p50": round(p(errs, 50) * 1e3, 3), "p99": round(p(errs, 99) * 1e3, 3),
                                         "max": round(max(errs) * 1e3, 3) if errs else None},
                    "monitor_own_ms": {"p50": round(p(own, 50) * 1e3, 3), "p99": round(p(own, 99) * 1e3, 3)}
                    if own else None,
                    **_common.machine()}), flush=True)
        finally:
            master.stop()
    p = _common.percentile
    print(json.dumps({"benchmark": "timed", "T_s": "all", "firings": len(all_errors),
                      "at_subscriber_p50_ms": round(p(all_errors, 50) * 1e3, 3),
                      "at_subscriber_p99_ms": round(p(all_errors, 99) * 1e3, 3),
                      # T = 0 fires at the message itself: no deadline, so no own error of the monitor
                      "monitor_own_p99_ms": round(p(all_own, 99) * 1e3, 3) if all_own else None,
                      "monitor_own_over": "every T but 0" if 0.0 in durations else "every T",
                      "target_p99_ms": 1.0, "met": bool(all_own) and p(all_own, 99) <= 0.001,
                      **_common.machine()}))


if __name__ == "__main__":
    sys.exit(main())
