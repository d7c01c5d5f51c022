"""bench/_common.py: nearest-rank percentiles and the machine facts every benchmark prints flat."""
import math
import os
import sys

import pytest

from conftest import ROOT

sys.path.insert(0, os.path.join(ROOT, "bench"))
import _common  # noqa: E402


def nearest_rank(values, q):
    """The definition: the smallest value with at least q % of the values at or below it."""
    s = sorted(values)
    for v in s:
        if sum(x <= v for x in s) * 100 >= q * len(s):
            return v
    return s[-1]


@pytest.mark.parametrize("n", [1, 2, 3, 4, 5, 10, 20, 50, 99, 100, 101, 250])
@pytest.mark.parametrize("q", [0, 1, 10, 25, 50, 75, 90, 99, 99.9, 100])
def test_percentile_is_the_true_nearest_rank(n, q):
    values = [float(i) for i in range(n, 0, -1)]  # distinct, unsorted
    assert _common.percentile(values, q) == nearest_rank(values, q)


def test_an_integer_rank_is_that_rank_not_the_next():
    # q*n/100 an odd integer: round-half-even in the old formula took the rank above it
    assert _common.percentile(range(1, 11), 50) == 5  # rank 5 of 10
    assert _common.percentile(range(1, 101), 99) == 99  # rank 99 of 100
    assert _common.percentile(range(1, 3), 50) == 1  # rank 1 of 2
    assert _common.percentile([7.0], 99) == 7.0


def test_percentile_of_nothing_is_nan():
    assert math.isnan(_common.percentile([], 50))


def test_machine_facts_are_flat_and_complete():
    facts = _common.machine()
    assert set(facts) == {"python", "cpus", "cpu", "loadavg_1min"}
    assert not any(isinstance(v, dict) for v in facts.values())
    assert isinstance(facts["cpus"], int) and isinstance(facts["loadavg_1min"], float)


@pytest.mark.parametrize("script", sorted(f for f in os.listdir(os.path.join(ROOT, "bench"))
                                          if f.endswith(".py") and not f.startswith("_")))
def test_every_benchmark_prints_the_machine_flat(script):
    text = open(os.path.join(ROOT, "bench", script), encoding="utf-8").read()
    assert '"machine": _common.machine()' not in text
    assert "machine()" in text, f"{script} prints no machine facts"


@pytest.mark.parametrize("script", sorted(f for f in os.listdir(os.path.join(ROOT, "bench"))
                                          if f.endswith(".py") and not f.startswith("_")))
def test_every_benchmark_help_starts_with_a_complete_sentence(script):
    import ast
    doc = ast.get_docstring(ast.parse(open(os.path.join(ROOT, "bench", script), encoding="utf-8").read()))
    first = doc.splitlines()[0]
    assert first.rstrip().endswith((".", ")")), f"{script}: --help's description stops mid-sentence: {first!r}"


def test_a_count_or_duration_of_0_is_a_usage_error_not_a_traceback():
    """A benchmark sweep: `--repeat 0`, `--messages 0`, `--seconds 0` … gave ZeroDivisionError, an empty
    max(), or NaN figures that are no JSON; `--cases xyz` measured nothing and said nothing."""
    import argparse

    count, seconds = _common.above_zero(int), _common.above_zero(float)
    assert count("3") == 3 and seconds("0.5") == 0.5 and _common.above_zero(int, zero_ok=True)("0") == 0
    for parse, text in ((count, "0"), (count, "-5"), (seconds, "0"), (seconds, "nan"), (seconds, "inf"),
                        (count, "x")):
        with pytest.raises(argparse.ArgumentTypeError):
            parse(text)
    import subprocess
    for script, args in (("parse_check.py", ["--repeat", "0"]), ("reaction.py", ["--seconds", "0"]),
                         ("cpu.py", ["--cases", "xyz"]), ("replay_throughput.py", ["--messages", "-5"])):
        out = subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "bench", script)] + args,
                             capture_output=True, text=True, timeout=60)
        assert out.returncode == 2 and "error: argument" in out.stderr and "Traceback" not in out.stderr, out.stderr
