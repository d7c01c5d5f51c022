#!/usr/bin/python3
"""How the monitor's CPU, drops and reaction grow with topics and rules; prints JSON per case.

Its CPU (share of one core), messages
dropped, and reaction p99, while it watches 10 / 50 / 200 topics at 100 Hz each with 10 / 100 /
1,000 rules, plus the target cases: 20 topics with 100 rules, and 100 topics with 100 rules
(10,000 load messages/s).

Targets: 20 topics x 100 Hz with 100 rules under 25 % of one core (`target_cpu_le_0.25`); no drops
in any case of up to 10,000 load messages/s plus the driver's 100 (`target_no_drops`, on every
case of at most 10,100 messages/s in all). Usage: bench/scale.py [--seconds S] [--smoke]
[--only 100x100 ...] [--receiver one_thread|rospy]
"""
import argparse
import json
import os
import re
import sys
import tempfile
import threading
import time

import psutil

import _common
from _rosbench import PrivateMaster, run_peer, spec_text, start_load, start_monitor, stop_processes


def cpu_share(pid, seconds, out):
    """Average CPU share of one core of a process over `seconds` (threads' run times)."""
    from rubass.ros.nodes import _schedstat_seconds

    t0, c0 = time.monotonic(), _schedstat_seconds(pid)
    time.sleep(seconds)
    t1, c1 = time.monotonic(), _schedstat_seconds(pid)
    out.append((c1 - c0) / (t1 - t0) if c0 is not None and c1 is not None else psutil.Process(pid).cpu_percent(1) / 100)


def case(master, tmp, topics, rules, seconds, receiver="one_thread"):
    load = start_load(master, topics, 100)
    mon = None
    try:
        mon, _ = start_monitor(master, tmp, spec_text(topics, rules), receiver=receiver)
        time.sleep(1.5)  # every load connection up
        shares = []
        sampler = threading.Thread(target=cpu_share, args=(mon.pid, seconds, shares))
        sampler.start()
        r = run_peer(master, ["driver", "rubass", "100", str(seconds)], seconds + 60)
        sampler.join()
    finally:
        stop_processes(load)
        if mon is not None:
            stop_processes([mon])
    log = open(os.path.join(tmp, "monitor.log")).read()
    m = re.search(r"stopped after (\d+) messages? \((\d+) dropped", log)
    lat = r["latencies"]
    p = _common.percentile
    return {
        "benchmark": "scale", "receiver": receiver, "topics": topics, "rules": rules + 1, "messages_per_s": topics * 100 + 100,
        "monitor_cpu_share": round(shares[0], 3) if shares else None,
        "received": int(m.group(1)) if m else None, "dropped": int(m.group(2)) if m else None,
        "reaction_p50_ms": round(p(lat, 50) * 1e3, 3), "reaction_p99_ms": round(p(lat, 99) * 1e3, 3),
        "unanswered": r["unanswered"], **_common.machine(),
    }


def _case_name(text):
    """`100x100` -> (100, 100): topics and rules of a case of the grid."""
    try:
        topics, rules = (int(x) for x in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not TOPICSxRULES, e.g. 100x100") from None
    return topics, rules


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=_common.above_zero(float), default=5.0,
                    help="measured seconds per case (default 5)")
    ap.add_argument("--smoke", action="store_true", help="one short case (10 topics, 10 rules), to check it works")
    _common.receiver_option(ap)
    ap.add_argument("--only", metavar="TOPICSxRULES", nargs="+", type=_case_name,
                    help="only these cases of the grid, e.g. 100x100 200x1000")
    args = ap.parse_args()
    grid = [(10, 10)] if args.smoke else \
        [(20, 100), (100, 100)] + [(t, r) for t in (10, 50, 200) for r in (10, 100, 1000)]
    if args.only:
        unknown = [f"{t}x{r}" for t, r in args.only if (t, r) not in grid]
        if unknown:
            ap.error(f"argument --only: not a case of the grid: {', '.join(unknown)} (the grid: "
                     f"{', '.join(f'{t}x{r}' for t, r in grid)})")
        grid = [c for c in grid if c in args.only]
    with tempfile.TemporaryDirectory() as tmp:
        master = PrivateMaster(os.path.join(tmp, "home"))
        try:
            for topics, rules in grid:
                res = case(master, tmp, topics, rules, 1.0 if args.smoke else args.seconds, args.receiver)
                if (topics, rules) == (20, 100):
                    res["target_cpu_le_0.25"] = res["monitor_cpu_share"] is not None and res["monitor_cpu_share"] <= 0.25
                if res["messages_per_s"] <= 10100:
                    res["target_no_drops"] = res["dropped"] == 0
                print(json.dumps(res), flush=True)
        finally:
            master.stop()


if __name__ == "__main__":
    sys.exit(main())
