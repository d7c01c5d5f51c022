"""The benchmarks run (in a short smoke mode) and print the JSON they promise."""
import json
import os
import subprocess
import sys

import pytest

from conftest import ROOT


def bench(name, *args, tmp=None):
    out = subprocess.run([sys.executable, os.path.join(ROOT, "bench", name), *args], capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    return [json.loads(line) for line in out.stdout.splitlines()]


def test_parse_check():
    (figures,) = bench("parse_check.py", "--rules", "50", "--repeat", "1")
    assert figures["rules"] == 50 and figures["parse_and_check_s_median"] > 0


def test_engine_message():
    rows = bench("engine_message.py", "--messages", "300")
    assert [r["rules"] for r in rows] == [10, 100, 1000] and all(r["mean_us"] > 0 for r in rows)


def test_for_deadline():
    (figures,) = bench("for_deadline.py", "--firings", "5")
    assert figures["firings"] == 5 and figures["max_ms"] >= figures["p50_ms"] >= 0


@pytest.mark.ros
def test_replay_throughput(tmp_path):
    pytest.importorskip("rosbag")
    (figures,) = bench("replay_throughput.py", "--messages", "4000", "--dir", str(tmp_path))
    assert figures["messages"] == 4000 and figures["messages_per_s"] > 0
