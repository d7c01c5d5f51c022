"""bench/cpu.py runs with tiny sizes and prints the JSON it promises (monitor beside a bare subscriber)."""
import json
import os
import subprocess
import sys

import pytest

from conftest import ROOT


@pytest.mark.ros
@pytest.mark.slow
def test_cpu_benchmark_smoke():
    if not os.path.exists("/usr/bin/rosmaster"):
        pytest.skip("ROS 1 is not installed")
    out = subprocess.run([sys.executable, os.path.join(ROOT, "bench", "cpu.py"), "--smoke"], capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    rows = [json.loads(line) for line in out.stdout.splitlines()]
    assert [(r["case"], r.get("profile")) for r in rows] == [("a", None), ("b", None), ("c", "a"), ("c", "b")]
    assert {r["receiver"] for r in rows} == {"one_thread"}  # the monitor's default ~receiver
    for r in rows[:2]:
        # every message published reached both subscribers, and both spent CPU on them
        assert r["published"] > 0 and r["bare_received"] == r["published"]
        assert r["monitor_received"] == r["published"] and r["monitor_dropped"] == 0
        assert r["monitor_cpu_us_per_msg"] > 0 and r["bare_cpu_us_per_msg"] > 0
        assert r["ratio"] == pytest.approx(r["monitor_cpu_us_per_msg"] / r["bare_cpu_us_per_msg"], rel=0.05)
        assert isinstance(r["target_ratio_le_1.5"], bool)
    for r in rows[2:]:
        assert r["steps"] and r["bare_kept_msgs_per_s"] > 0 and isinstance(r["target_monitor_ge_0.8_bare"], bool)
