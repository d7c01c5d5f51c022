#!/usr/bin/python3
"""How late a `for` fires after a violation followed by silence, through EngineLoop; prints JSON.

The error is the instant the engine thread hands over a
`start` minus t0 + T, where t0 is the violating message and nothing follows it (the case
where monitors that wait for the next message or tick are late).

Target (issue 17): p99 <= 0.5 ms. Optionally with a CPU-bound thread in the process (--busy), the GIL case.
Usage: bench/for_deadline.py [--firings N] [--busy] [--default-slack]
"""
import argparse
import json
import random
import sys
import threading
import time

import _common  # noqa: F401
from rubass.engine import Engine  # noqa: E402
from rubass.engine.loop import EngineLoop, Message  # noqa: E402
from rubass.lang import check_text  # noqa: E402
from rubass.ros.timerslack import exact_timers  # noqa: E402

SPEC = "action primitive warn;\nentity a { rules: r: (topic /x.data > 1) for %s s; }\nif (a.r) then { warn; }\n"


def measure(durations, busy, default_slack=False):
    errors = []
    stop = threading.Event()
    if busy:
        sys.setswitchinterval(0.0005)  # what the monitor does (ros1-notes: GIL switch interval)

        def spin():
            x = 0
            while not stop.is_set():
                x += 1
        threading.Thread(target=spin, daemon=True).start()
    for T in durations:
        spec = check_text(SPEC % T, _common.os.path.join(_common.ROOT, "b.rbs"), [_common.LIB])
        clock = time.monotonic
        engine = Engine(spec, clock())
        engine.evaluate_all(clock())
        fired = threading.Event()
        seen = {}

        def handler(events, cause, seen=seen, fired=fired):
            now = time.monotonic()
            for e in events:
                if e.kind == "start":
                    seen["at"] = now
                    seen["event_time"] = e.time
                    fired.set()

        loop = EngineLoop(engine, clock, 50.0, handler)
        def engine_thread(loop=loop):
            if not default_slack:
                exact_timers()  # what the monitor's engine thread does
            loop.run()
        thread = threading.Thread(target=engine_thread, daemon=True)
        thread.start()
        t0 = clock()
        loop.submit(Message("/x", t0, {"data": 2.0}))
        fired.wait(T + 2.0)
        loop.stop()
        thread.join()
        if "at" not in seen:
            raise SystemExit(f"T={T}: never fired")
        assert seen["event_time"] == t0 + T
        errors.append(seen["at"] - (t0 + T))
    stop.set()
    return errors


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--firings", type=_common.above_zero(int), default=300,
                    help="firings, each with a random T in [0, 0.1] s (default 300)")
    ap.add_argument("--busy", action="store_true", help="a CPU-bound thread runs in the process")
    ap.add_argument("--default-slack", action="store_true",
                    help="leave the engine thread's timer slack at Linux's default (50 us), for comparison")
    args = ap.parse_args()
    rng = random.Random(7)
    durations = [round(rng.uniform(0.0, 0.1), 4) for _ in range(args.firings)]
    errs = measure(durations, args.busy, args.default_slack)
    print(json.dumps({
        "benchmark": "for_deadline", "firings": len(errs), "busy_thread": args.busy,
        "timer_slack": "default" if args.default_slack else "1 ns",
        "p50_ms": round(_common.percentile(errs, 50) * 1e3, 3),
        "p99_ms": round(_common.percentile(errs, 99) * 1e3, 3),
        "max_ms": round(max(errs) * 1e3, 3), "min_ms": round(min(errs) * 1e3, 3),
        "target_p99_ms": 0.5, "met": _common.percentile(errs, 99) <= 0.0005, **_common.machine(),
    }))


if __name__ == "__main__":
    main()
