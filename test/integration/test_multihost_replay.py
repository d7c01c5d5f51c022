"""`rubass replay` of a multi-host run: the agents' recorded reports stand for the nodes on other hosts."""
import json
import os
import subprocess
import sys

import pytest

rosbag = pytest.importorskip("rosbag")
import rospy  # noqa: E402
from std_msgs.msg import String  # noqa: E402

from conftest import ROOT  # noqa: E402

pytestmark = pytest.mark.ros
T0 = 1700000000.0
SPEC = ('import "lib.yaml";\naction primitive stop;\n'
        "entity arm: hog { rules: busy: cpu(node hog) > 50 %; }\nif (arm.busy) then { stop; }\n")
LIB = "actions:\n  stop: {plugin: log, level: warn}\n"


def agent_report(t, cpu, pid=42):
    return String(data=json.dumps({
        "agent": "/rubass_agent_arm", "host": "10.200.0.2", "addresses": ["10.200.0.2"], "time": T0 + t,
        "period": 0.1, "seq": 1, "nodes": [{"node": "/hog", "time": T0 + t, "alive": True, "cpu": cpu,
                                             "memory": 1e7, "pid": pid, "uri": "http://10.200.0.2:4000/",
                                             "why": "alive"}]}))


def run(tmp_path, items, caller=None):
    """Replay `items` recorded in a bag; `caller`: the agents' topic recorded as published by that node."""
    (tmp_path / "lib.yaml").write_text(LIB)
    (tmp_path / "s.rbs").write_text(SPEC)
    bag = str(tmp_path / "run.bag")
    with rosbag.Bag(bag, "w") as b:
        for t, topic, msg in items:
            header = None
            if caller is not None and topic == "/rubass/agent_samples":
                header = {"topic": topic, "type": msg._type, "md5sum": msg._md5sum,
                          "message_definition": msg._full_text, "callerid": caller}
            b.write(topic, msg, rospy.Time.from_sec(T0 + t), connection_header=header)
    proc = subprocess.run([sys.executable, "-m", "rubass", "replay", str(tmp_path / "s.rbs"), bag, "--json"],
                          cwd=ROOT, capture_output=True, text=True, timeout=120,
                          env=dict(os.environ, PYTHONPATH=ROOT))
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr
    return [json.loads(line) for line in proc.stdout.splitlines()], proc.stderr


def test_agent_reports_drive_cpu_and_a_silent_agent_makes_it_unknown(tmp_path):
    items = [(i * 0.1, "/rubass/agent_samples", agent_report(i * 0.1, 0.2 if i < 5 else 0.9)) for i in range(11)]
    items.append((3.0, "/other", String(data="end")))  # the recording goes on after the agent fell silent
    lines, stderr = run(tmp_path, items)
    assert "no node samples" not in stderr
    # the agents' reports alone: said, as the replay can differ from the monitor (docs/multihost.md)
    assert "has the agents' reports (/rubass/agent_samples) but not the monitor's ~node_samples" in stderr
    rule = [(x["time"], x["value"]) for x in lines if x["event"] == "rule"]
    assert [v for _, v in rule] == [None, False, True, None]
    assert rule[2][0] == pytest.approx(0.5, abs=1e-6)
    assert rule[3][0] == pytest.approx(1.0 + 0.3, abs=1e-6)  # three periods after the last report
    assert [x["time"] for x in lines if x["event"] == "start"] == [pytest.approx(0.5, abs=1e-6)]


def test_the_monitors_own_samples_win_over_an_agents_for_the_same_node(tmp_path):
    mon = [(i * 0.1, "/rubass/node_samples", String(data=json.dumps(
        {"node": "hog", "time": T0 + i * 0.1, "alive": True, "cpu": 0.1, "memory": 1e7}))) for i in range(10)]
    agent = [(i * 0.1 + 0.05, "/rubass/agent_samples", agent_report(i * 0.1, 0.9)) for i in range(10)]
    lines, _ = run(tmp_path, sorted(mon + agent, key=lambda x: x[0]))
    assert not [x for x in lines if x["event"] == "start"]
    assert {x["value"] for x in lines if x["event"] == "rule"} <= {None, False}


@pytest.mark.parametrize("caller,starts", [("/rubass_agent_arm", 1), ("/g", 0)])
def test_a_report_counts_only_from_the_agent_it_names_as_live(tmp_path, caller, starts):
    """Live, the monitor takes a report only from the node it names (its connection's callerid): a
    stray or forged one, a leaving one included, never stands in for the agent. Replay does the same."""
    items = [(i * 0.1, "/rubass/agent_samples", agent_report(i * 0.1, 0.9)) for i in range(10)]
    items.append((2.0, "/other", String(data="end")))
    lines, _ = run(tmp_path, items, caller=caller)
    assert len([x for x in lines if x["event"] == "start"]) == starts, lines


def test_a_filtered_bag_whose_topic_names_its_first_agent_keeps_every_agents_reports(tmp_path):
    """`rosbag filter`/`compress` write one connection per topic, under its first publisher's name: the
    reports of the other agents then carry that agent's name as publisher, and were all ignored."""
    other = String(data=agent_report(0.0, 0.9).data.replace("/rubass_agent_arm", "/rubass_agent_b"))
    first_agent = String(data=json.dumps({"agent": "/rubass_agent_arm", "host": "10.200.0.9", "period": 0.1,
                                          "time": T0, "nodes": []}))
    items = [(0.0, "/rubass/agent_samples", first_agent)]
    items += [(0.05 + i * 0.1, "/rubass/agent_samples", String(data=other.data)) for i in range(10)]
    items.append((2.0, "/other", String(data="end")))
    lines, stderr = run(tmp_path, items, caller="/rubass_agent_arm")
    assert len([x for x in lines if x["event"] == "start"]) == 1, (lines, stderr)


def test_a_spec_that_times_the_agents_topic_sees_its_reports(tmp_path):
    items = [(i * 0.1, "/rubass/agent_samples", agent_report(i * 0.1, 0.2)) for i in range(30)]
    (tmp_path / "lib.yaml").write_text(LIB)
    spec = ('import "lib.yaml";\naction primitive stop;\n'
            "entity arm: hog { rules: busy: cpu(node hog) > 50 %; silent: age(topic /rubass/agent_samples) > 0.5 s; }\n"
            "if (arm.busy or arm.silent) then { stop; }\n")
    bag = str(tmp_path / "run.bag")
    with rosbag.Bag(bag, "w") as b:
        for t, topic, msg in items:
            b.write(topic, msg, rospy.Time.from_sec(T0 + t))
    (tmp_path / "t.rbs").write_text(spec)
    proc = subprocess.run([sys.executable, "-m", "rubass", "replay", str(tmp_path / "t.rbs"), bag, "--json"],
                          cwd=ROOT, capture_output=True, text=True, timeout=120, env=dict(os.environ, PYTHONPATH=ROOT))
    lines = [json.loads(line) for line in proc.stdout.splitlines()]
    assert proc.returncode == 0 and not [x for x in lines if x["event"] == "start"], (lines, proc.stderr)
