"""docs/failure-modes.md, latch state file: two monitors named /rubass on one machine, each with its own
master (two simulated robots), with one ROS_HOME, share no latch state file: B does not restore A's
latched stop, B's ~reset does not erase it, and A, restarted against the same master (after that
master's own restart on the same port, spelled `localhost` instead of 127.0.0.1), holds it again."""
import json
import os
import signal

import pytest
from conftest import ROOT
from rosharness import PY, Ros, spec, wait_log
from test_reliability_latch import BODY, stops_within, trigger_and_clear

pytestmark = [pytest.mark.ros, pytest.mark.slow]


def test_two_masters_on_one_machine_share_no_latch_state(ros, tmp_path):
    path = spec(tmp_path, BODY)
    (tmp_path / "b").mkdir()
    rb = Ros(tmp_path / "b")  # a second master, on another port, with the same ROS_HOME
    try:
        rb.env["ROS_HOME"] = ros.env["ROS_HOME"]
        a = ros.monitor(path)
        trigger_and_clear(ros)
        home = tmp_path / "ros_home" / "rubass"
        assert sorted(os.listdir(home)) == [f"rubass.{ros.port}.latches.json"]
        b = rb.monitor(path)
        assert stops_within(rb, 1.0) == [], f"B restored A's latch:\n{rb.log(b)}"
        out = rb.call("/rubass/reset")
        assert out.returncode == 0 and "released 0 latched behaviours" in out.stdout, out.stdout
        assert json.loads((home / f"rubass.{ros.port}.latches.json").read_text())["latched"], "A's file is A's"
        os.killpg(a.pid, signal.SIGKILL)
        a.wait(10)
        ros.master.restart()  # the same port: the same master for the latch state
        env = dict(ros.env, ROS_MASTER_URI=f"http://localhost:{ros.port}")
        a2 = ros.spawn([PY, os.path.join(ROOT, "scripts", "monitor"), "__name:=rubass", f"_spec:={path}"],
                       "monitor-a2", env=env)
        ros.wait_service("/rubass/reset", a2)
        wait_log(a2, ros, "active again until ~reset")
        assert len(stops_within(ros, 1.0)) >= 10, f"A's latched stop is held again:\n{ros.log(a2)}"
        assert stops_within(rb, 1.0) == [], "and B still stops for nothing"
    finally:
        rb.stop()
