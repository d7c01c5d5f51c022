"""bench/engine_v2.py runs in a short smoke mode and prints the JSON it promises (no ROS)."""
import json
import os
import subprocess
import sys

from conftest import ROOT


def test_engine_v2_benchmark_smoke():
    out = subprocess.run([sys.executable, os.path.join(ROOT, "bench", "engine_v2.py"), "--messages", "400",
                          "--scans", "20", "--rules", "30", "--repeat", "1"],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    rows = [json.loads(line) for line in out.stdout.splitlines()]
    assert [r["figure"] for r in rows] == ["per_message"] * 3 + ["laser_scan", "parse_check"]
    assert all(r["benchmark"] == "engine_v2" for r in rows)
    per_message, laser, parse = rows[:3], rows[3], rows[4]
    assert [r["rules"] for r in per_message] == [10, 100, 1000]
    for r in per_message:
        # the rules the messages feed were evaluated: each has a value, and they changed
        assert r["unknown_at_end"] == [] and r["events"] >= r["dependent_rules"]
        assert r["p99_us"] >= r["p50_us"] > 0 and isinstance(r["met"], bool)
    assert laser["beams"] == 1081 and laser["scans"] == 20 and laser["unknown_at_end"] == []
    assert laser["mean_us"] > 0
    assert parse["rules"] == 30 and parse["parse_and_check_s_median"] > 0
    assert {"python", "cpus"} <= set(parse)
