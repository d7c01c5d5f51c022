"""An agent whose name another node takes (a second `rosrun rubass agent` on the host) is shut down by
the master; it must not send its leaving report, which carries the name the new agent reports under,
and would make the monitor drop the new agent (review finding: rospy had closed the topic, so it
failed and logged "the leaving report could not be sent")."""
import json
import os
import time

import pytest
from rosharness import PY, wait_log

from conftest import ROOT

pytestmark = pytest.mark.ros


def test_an_agent_whose_name_is_taken_sends_no_leaving_report(ros):
    agent = [PY, os.path.join(ROOT, "scripts", "agent"), "__name:=rubass_agent_h"]
    listener = ros.probe_bg({"listen": [{"topic": "/rubass/agent_samples", "type": "std_msgs/String"}],
                             "steps": [{"sleep": 12}]}, name="listener")
    first = ros.spawn(agent, "agent1")
    wait_log(first, ros, "reporting the nodes on host", timeout=20)
    time.sleep(1.0)
    second = ros.spawn(agent, "agent2")
    first.wait(timeout=20)  # the master shut it down
    wait_log(second, ros, "reporting the nodes on host", timeout=20)
    time.sleep(1.0)
    listener.kill()
    out, _ = listener.communicate(timeout=10)
    reports = [json.loads(json.loads(line)["msg"]["data"]) for line in out.splitlines()
               if line.startswith("{") and '"recv"' in line]
    assert reports and not [r for r in reports if r.get("leaving")], [r for r in reports if r.get("leaving")]
    log = ros.log(first)  # said as what it is, not as a failed leaving report
    assert "another node took this agent's name" in log and "could not be sent" not in log, log
