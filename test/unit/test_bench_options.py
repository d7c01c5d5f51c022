"""Benchmark options that choose what is measured are checked before anything runs."""
import os
import subprocess
import sys

import pytest

from conftest import ROOT

BENCH = os.path.join(ROOT, "bench")
pytestmark = pytest.mark.skipif(not os.path.exists("/usr/bin/rosmaster"), reason="the ROS benchmarks need ROS 1")


def run(script, *args):
    return subprocess.run([sys.executable, os.path.join(BENCH, script), *args], capture_output=True, text=True,
                          timeout=60)


@pytest.mark.parametrize("args, said", [
    (["--only", "3x3"], "argument --only: not a case of the grid: 3x3 (the grid: 20x100, 100x100, 10x10,"),
    (["--only", "100"], "argument --only: '100' is not TOPICSxRULES, e.g. 100x100"),
    (["--receiver", "threads"], "argument --receiver: invalid choice: 'threads'"),
])
def test_scale_refuses_a_case_or_receiver_it_does_not_have(args, said):
    out = run("scale.py", *args)
    assert out.returncode == 2 and said in out.stderr and "Traceback" not in out.stderr, out.stderr


def test_cpu_refuses_a_receiver_the_monitor_does_not_have():
    out = run("cpu.py", "--receiver", "threads")
    assert out.returncode == 2 and "argument --receiver: invalid choice: 'threads'" in out.stderr, out.stderr
