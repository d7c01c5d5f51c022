"""The acceptance tester's case on three network namespaces (test_multihost.py's cluster): an agent at
50 Hz on the arm's host, a stop held on a CPU hog there, and an unrelated node of that host hung
with SIGSTOP. Each report used to wait for the hung node's 100 ms getPid, the monitor (3 periods:
60 ms) took the agent for silent, the hog's cpu() went unknown and the stop was released (the rule read
unknown). The stop itself is not asserted: on a loaded machine the hog may really calm down."""
import json
import os
import signal
import time

import pytest

from conftest import ROOT
from test_multihost import PY, cluster, events, lines, wait_for  # noqa: F401 (cluster: a fixture)

pytestmark = [pytest.mark.ros, pytest.mark.slow]


def test_a_hung_node_leaves_the_other_nodes_of_its_host_known_to_the_monitor(cluster, tmp_path):  # noqa: F811
    (tmp_path / "lib.yaml").write_text("actions:\n  stop: {plugin: publish, topic: /safety_cmd, type: "
                                       "geometry_msgs/Twist, message: {}, rate: 20 Hz}\n")  # not latched
    spec = str(tmp_path / "safety.rbs")
    open(spec, "w").write('import "lib.yaml";\naction primitive stop;\n'
                          "entity arm: hog { rules: busy: (cpu(node hog) > 20 %) for 0.5 s; }\n"
                          "if (arm.busy) then { stop; }\n")
    for host in ("robot", "safety"):
        cluster.agent(host)
    cluster.spawn("arm", [PY, os.path.join(ROOT, "scripts", "agent"), "_node_rate:=50"], "agent-arm")
    cluster.node("arm", "hog", "hog")
    frozen = cluster.node("arm", "frozen", "talk", "/arm_state", "5")
    watch = cluster.listen("safety", "watch", "/diagnostics:diagnostic_msgs/DiagnosticArray",
                           "/rubass/events:std_msgs/String", "/rubass/agent_samples:std_msgs/String",
                           "/rubass/node_samples:std_msgs/String")
    cluster.spawn("safety", [PY, os.path.join(ROOT, "scripts", "monitor"), "__name:=rubass", f"_spec:={spec}",
                             "_diagnostics_rate:=5", "_node_rate:=50"], "monitor")  # the agent's rate, as documented
    wait_for(cluster, "the stop started", lambda: [e for e in events(watch) if e["event"] == "start"], timeout=40)
    arm = cluster.net.address["arm"]

    def frozen_measured():
        reports = [json.loads(r["msg"]["data"]) for r in lines(watch) if r["topic"] == "/rubass/agent_samples"]
        return [r for r in reports if r["host"] == arm and any(
            n["node"] == "/frozen" and n["cpu"] is not None for n in r["nodes"])]

    wait_for(cluster, "the arm's agent measures /frozen", frozen_measured)
    time.sleep(1.0)
    os.kill(frozen.pid, signal.SIGSTOP)
    try:
        hung = time.time()
        time.sleep(4.0)
    finally:
        os.kill(frozen.pid, signal.SIGCONT)
    # what the monitor used for the hog, sample by sample (50 Hz): measured, not unknown for a silent agent
    used = [json.loads(r["msg"]["data"]) for r in lines(watch)
            if r["topic"] == "/rubass/node_samples" and hung + 0.5 < r["wall"] < hung + 4.0]
    hog = [u for u in used if u["node"] == "hog"]
    unknown = [u for u in hog if u["cpu"] is None]
    # (a few may be on a loaded machine: 50 Hz leaves the agent 60 ms; with each report waiting for the
    # hung node's 100 ms getPid, about 40 % were)
    assert len(hog) > 50 and len(unknown) <= 0.05 * len(hog), (len(unknown), len(hog), cluster.logs())


def test_sigterm_stops_an_agent_whose_host_is_cut_off_from_the_master(cluster):  # noqa: F811
    """The tester's second case: with the link cut, the agent ignored SIGTERM until the link came back."""
    agent = cluster.spawn("arm", [PY, os.path.join(ROOT, "scripts", "agent"), "_node_rate:=10"], "agent-arm")
    wait_for(cluster, "the agent reporting", lambda: "reporting the nodes" in cluster.log(agent))
    time.sleep(1.0)
    cluster.net.cut("arm")
    wait_for(cluster, "the agent notices the master is unreachable", lambda: "cannot be reached" in cluster.log(agent))
    sent = time.time()
    os.kill(agent.pid, signal.SIGTERM)
    try:
        code = agent.wait(20)
    except Exception:
        code = None
    took = time.time() - sent
    log = cluster.log(agent)
    assert code == 0 and took < 8.0, (code, took, log)
    assert "did not know this node" not in log and "Traceback" not in log, log
