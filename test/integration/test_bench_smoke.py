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


def test_fuzz():
    (figures,) = bench("fuzz.py", "--cases", "50", "--seed", "1")
    assert figures["cases"] == 50 and figures["tracebacks"] == 0


def test_for_deadline():
    (figures,) = bench("for_deadline.py", "--firings", "5")
    assert figures["firings"] == 5 and figures["max_ms"] >= figures["p50_ms"] >= 0


@pytest.mark.ros
def test_replay_throughput(tmp_path):
    pytest.importorskip("rosbag")
    (figures,) = bench("replay_throughput.py", "--messages", "4000", "--dir", str(tmp_path))
    assert figures["messages"] == 4000 and figures["messages_per_s"] > 0


@pytest.mark.ros
@pytest.mark.parametrize("script", ["reaction.py", "timed.py", "scale.py", "reload.py", "master_restart.py",
                                    "reload_storm.py", "soak.py"])
def test_ros_benchmarks(script):
    if not os.path.exists("/usr/bin/rosmaster"):
        pytest.skip("ROS 1 is not installed")
    rows = bench(script, "--smoke")
    assert rows and all(r["benchmark"] == script[:-3] for r in rows)
    if script == "reaction.py":
        assert rows[0]["raw_hop"]["n"] > 0 and rows[0]["rubass"]["n"] > 0
        assert rows[0]["rubass_unanswered"] == 0 and rows[0]["rubass_extra_stops"] == 0
    if script in ("reload_storm.py", "soak.py"):  # their --smoke: a short run of the same measurement
        assert rows[0]["missed"] == 0 and rows[0]["monitor_alive"] and rows[0]["violations"] > 0
    if script == "reload.py":
        assert rows[0]["reloads"] == 2 and rows[0]["missed"] == 0
    if script == "master_restart.py":
        assert rows[0]["restarts"] == 1 and rows[0]["missed"] == 0 and rows[0]["blind_after_master_up_ms_max"] < 1000
