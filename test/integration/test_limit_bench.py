"""bench/limit_latency.py runs (smoke mode) and prints the JSON it promises."""
import json
import os
import subprocess
import sys

import pytest

from conftest import ROOT

pytestmark = [pytest.mark.ros, pytest.mark.slow]


def test_limit_latency_bench_smoke():
    if not os.path.exists("/usr/bin/rosmaster"):
        pytest.skip("ROS 1 is not installed")
    out = subprocess.run([sys.executable, os.path.join(ROOT, "bench", "limit_latency.py"), "--smoke"],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    (figures,) = [json.loads(line) for line in out.stdout.splitlines()]
    assert figures["benchmark"] == "limit_latency" and figures["samples_per_path"] == 50
    assert all(figures["paths"][p]["n"] == 50 for p in ("raw", "relay", "limit")), figures["lost"]
    assert figures["clamped_wrong"] == [] and figures["paths"]["raw"]["p50_ms"] > 0
    assert isinstance(figures["met"], bool)  # a figure, not a timed test: the machine may be loaded
