"""A log folder rospy cannot make (ROS_LOG_DIR unwritable, a file in its way, another user's folder
above it) made rospy print one WARNING and then send every log line of the node to /rosout only:
a monitor that could not use its spec said so nowhere on its console. Its lines now still print."""
import os

import pytest
from rosharness import PY, spec, wait_log

from conftest import ROOT

pytestmark = [pytest.mark.ros, pytest.mark.slow]


def start(ros, tmp_path, body, name):
    (tmp_path / "a_file").write_text("")
    env = dict(ros.env, ROS_LOG_DIR=str(tmp_path / "a_file" / "log"))  # cannot be made
    return ros.spawn([PY, os.path.join(ROOT, "scripts", "monitor"), f"_spec:={spec(tmp_path, body, name=name)}",
                      f"_state_file:={tmp_path / 'latches.json'}"], "monitor-nolog", env=env)


def test_a_monitor_whose_log_folder_cannot_be_made_still_says_why_it_does_not_enforce(ros, tmp_path):
    mon = start(ros, tmp_path, "entity a { rules: r: topic /x.data > LIMT; }\nif (a.r) then { stop; }\n", "bad.rbs")
    wait_log(mon, ros, "NOT ENFORCING ANY RULE: cannot use the spec", timeout=20)
    log = ros.log(mon)
    assert "cannot create log directory" in log  # rospy's own line, first
    assert "bad.rbs:3:38: error: undefined name 'LIMT'" in log, log


def test_and_says_that_it_enforces(ros, tmp_path):
    mon = start(ros, tmp_path, "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { stop; }\n", "good.rbs")
    wait_log(mon, ros, "rubass: enforcing", timeout=20)
    assert ros.log(mon).count("rubass: enforcing") == 1  # once: not a second console handler
