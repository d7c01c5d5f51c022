#!/usr/bin/python3
"""The blind window after a master restart, and the monitor's reactions after it; prints JSON.

The master is SIGKILLed, down for --down seconds,
and started again on the same port, knowing nothing. Measured each time: how long after the
new master answers it knows the monitor again (the window in which a node started after the
restart cannot reach it), and the monitor's reactions to a driver started after the restart.
Usage: bench/master_restart.py [--restarts N] [--down S] [--rate HZ] [--smoke]
"""
import argparse
import json
import os
import re
import tempfile
import time

import _common
from _rosbench import PrivateMaster, run_peer, spec_text, start_monitor, stop_processes


def known(master, topic, node="/rubass"):
    pubs, subs, _ = master.getSystemState()
    return any(t == topic and node in n for t, n in subs) and any(t == "/bench/stop" and node in n for t, n in pubs)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--restarts", type=_common.above_zero(int), default=10, help="master restarts (default 10)")
    ap.add_argument("--down", type=_common.above_zero(float), default=1.0, help="seconds without a master each time")
    ap.add_argument("--rate", type=_common.above_zero(float), default=4.0, help="the monitor's ~master_rate (Hz)")
    ap.add_argument("--smoke", action="store_true", help="one restart, during the monitor's start-up")
    args = ap.parse_args()
    restarts = 1 if args.smoke else args.restarts
    import rosgraph

    windows, lat, expected, unanswered = [], [], 0, 0
    with tempfile.TemporaryDirectory() as tmp:
        master = PrivateMaster(os.path.join(tmp, "home"))
        try:
            mon, _ = start_monitor(master, tmp, spec_text(1, 0), master_rate=args.rate)
            for _ in range(restarts):
                master.restart(down=args.down)
                api = rosgraph.Master("/bench", master_uri=master.uri)
                while not known(api, "/bench/cmd"):
                    if time.time() - master.online_at > 30:
                        raise SystemExit("the monitor never re-registered")
                    time.sleep(0.002)
                windows.append(time.time() - master.online_at)
                out = run_peer(master, ["driver", "rubass", "20", "1"], 60)  # a node started after the restart
                lat += out["latencies"]
                expected += out["expected"]
                unanswered += out["unanswered"]
            with open(os.path.join(tmp, "monitor.log")) as fh:
                calls = [float(m) for m in re.findall(r"services again in ([0-9.]+) ms", fh.read())]
        finally:
            stop_processes([p for p in [locals().get("mon")] if p is not None])
            master.stop()
    ms = lambda v: round(v * 1000.0, 2)  # noqa: E731
    print(json.dumps({
        "benchmark": "master_restart", "restarts": restarts, "down_s": args.down, "master_rate_hz": args.rate,
        "blind_after_master_up_ms_p50": ms(_common.percentile(windows, 50)),
        "blind_after_master_up_ms_max": ms(max(windows)),
        "re_registration_ms_max": max(calls) if calls else None,
        "reaction_after_restart_ms_p50": ms(_common.percentile(lat, 50)),
        "reaction_after_restart_ms_p99": ms(_common.percentile(lat, 99)),
        "violations": expected, "missed": unanswered, **_common.machine()}))


if __name__ == "__main__":
    main()
