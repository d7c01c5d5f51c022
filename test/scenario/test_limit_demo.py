"""Scenario: the Kobuki-like base that creeps near an obstacle, may only back away while its
bumper is pressed, and stops at its zone's border (config/kobuki_creep.rbs, LANGUAGE.md §16),
through `rubass experiments` on the simulated base with its laser and bumper."""
import json
import os
import subprocess
import sys

import pytest

from conftest import ROOT

pytestmark = [pytest.mark.ros, pytest.mark.slow]

ROWS = ["Creep", "Back away", "Zone stop"]


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    if not os.path.exists("/usr/bin/rosmaster"):
        pytest.skip("ROS 1 is not installed")
    out = tmp_path_factory.mktemp("limit_demo")
    proc = subprocess.run([sys.executable, "-m", "rubass", "experiments", "--reps", "1", "--out", str(out),
                           "--only", *ROWS], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert "Traceback" not in proc.stderr, proc.stderr
    with open(out / "table.json") as fh:
        return proc, json.load(fh), out


def events(out, row):
    with open(out / "runs" / row.replace(" ", "_") / "0" / "events.jsonl") as fh:
        return [json.loads(line) for line in fh]


def test_every_limit_row_reacts_within_target_and_shows_in_table_and_plot(table):
    proc, data, out = table
    assert [r["row"] for r in data["rows"]] == ROWS
    for r in data["rows"]:
        assert r["stopped"] == 1 and not r["errors"], (r["row"], r["errors"], proc.stdout)
        assert r["paper"] is None and r["ideal"] - 0.005 <= r["a"]["max"] < 0.1, (r["row"], r["a"])
        # the table's own target is 10 ms; one run on a machine shared by other jobs gets some slack
        assert r["b"]["p99"] <= 0.050, (r["row"], r["b"])
    assert proc.returncode in (0, 1) and "Table 1 (seconds)" in proc.stdout, proc.stdout + proc.stderr
    assert "Creep" in proc.stdout and "not in the paper" in proc.stdout
    assert (out / "table.png").read_bytes()[:4] == b"\x89PNG"


def test_the_base_creeps_then_may_only_back_away_once_it_touches_the_obstacle(table):
    _, _, out = table
    ev = {e["event"]: e for e in events(out, "Back away")}
    assert ev["creep_received"]["linear"] == pytest.approx(0.1)  # the planner's 0.3 m/s, clamped
    assert ev["obstacle_near"]["wall"] < ev["creep_received"]["wall"] < ev["bumper_pressed"]["wall"]
    # the creep took it from 0.8 m to contact: seconds at 0.1 m/s, not a fraction of one at 0.3 m/s
    assert ev["bumper_pressed"]["wall"] - ev["obstacle_near"]["wall"] > 3.0
    assert ev["escape_received"]["linear"] <= 0.0
    assert "boundary" not in ev


def test_the_zone_stop_outranks_nothing_else_it_needs_and_stops_at_the_border(table):
    _, _, out = table
    ev = {e["event"]: e for e in events(out, "Zone stop")}
    assert "obstacle_near" not in ev and "bumper_pressed" not in ev
    assert 0 <= ev["stop_received"]["wall"] - ev["boundary"]["wall"] < 0.1
