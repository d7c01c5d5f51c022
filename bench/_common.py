"""Helpers shared by the benchmarks: the repository on sys.path, percentiles, machine facts, counts."""
import argparse
import math
import os
import platform
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")


def percentile(values, q):
    """The q-th percentile (0..100) by nearest rank: the ceil(q/100 * n)-th smallest value (1-based;
    the smallest for q = 0); NaN for no values."""
    s = sorted(values)
    if not s:
        return float("nan")
    rank = math.ceil(q * len(s) / 100.0 - 1e-9)  # q * n / 100 exactly an integer is that rank, not the next
    return s[max(1, min(len(s), rank)) - 1]


def machine():
    """Facts about the machine, flat in every benchmark's JSON: Python, CPUs, the CPU model and the
    1-minute load average when the figure was printed (the machine may be shared)."""
    model = ""
    try:
        with open("/proc/cpuinfo") as fh:
            model = next((line.split(":", 1)[1].strip() for line in fh if line.startswith("model name")), "")
    except OSError:
        pass
    return {"python": platform.python_version(), "cpus": os.cpu_count(), "cpu": model,
            "loadavg_1min": round(os.getloadavg()[0], 2)}


def above_zero(kind, zero_ok=False):
    """An argparse type: a finite number of `kind` (int or float) above 0 (or 0 too), else a usage error
    (a count of 0 gave a ZeroDivisionError, or NaN figures that are no JSON)."""
    def parse(text):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"invalid {kind.__name__} value: {text!r}") from None
        if not math.isfinite(value) or value < 0 or (value == 0 and not zero_ok):
            raise argparse.ArgumentTypeError(f"must be {'0 or more' if zero_ok else 'above 0'}, not {text}")
        return value

    parse.__name__ = kind.__name__
    return parse


def receiver_option(ap):
    """`--receiver`: the monitor's ~receiver for this run (docs/monitor.md), to compare its two ways of reading."""
    ap.add_argument("--receiver", choices=("one_thread", "rospy"), default="one_thread",
                    help="the monitor's ~receiver (default one_thread; rospy: a rospy thread per connection)")
