#!/usr/bin/python3
"""Fuzzes specs and action libraries through `rubass check`: clean errors only, never a traceback.

The whole front end (spec + YAML action library, from disk, through `rubass check`)
with thousands of hypothesis cases: only clean errors, never a traceback (test/fuzzing.py).
Prints one JSON line: cases, how many checked clean or with errors, time per case.
Usage: bench/fuzz.py [--cases N] [--seed S]
"""
import argparse
import json
import os
import sys
import tempfile
import time

import _common

sys.path.insert(0, os.path.join(_common.ROOT, "test"))
from fuzzing import clean_errors_only, spec_and_library  # noqa: E402
from hypothesis import HealthCheck, given, seed, settings  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=_common.above_zero(int), default=5000, help="hypothesis cases (default 5000)")
    ap.add_argument("--seed", type=int, default=int(time.time()), help="random seed (default: the time)")
    args = ap.parse_args()
    counts = {0: 0, 1: 0}
    with tempfile.TemporaryDirectory() as tmp:
        @seed(args.seed)
        @settings(max_examples=args.cases, deadline=None, database=None,
                  suppress_health_check=list(HealthCheck))
        @given(spec_and_library())
        def run(case):
            counts[clean_errors_only(tmp, *case)] += 1

        t0 = time.perf_counter()
        run()  # a failing case raises, with hypothesis's shrunk example: the bench then fails
        seconds = time.perf_counter() - t0
    n = counts[0] + counts[1]
    print(json.dumps({"benchmark": "fuzz", "cases": n, "checked_clean": counts[0], "clean_errors": counts[1],
                      "tracebacks": 0, "seed": args.seed, "seconds": round(seconds, 2),
                      "ms_per_case": round(seconds / max(n, 1) * 1000, 2), **_common.machine()}))


if __name__ == "__main__":
    main()
