"""Issue 18, monitor side, for real (network namespaces, fixtures of test_multihost.py): a
report claiming the hog's host neither reaches the rule nor passes unnoticed, and a second
agent on one host killed gives the same events live and in `rubass replay`."""
import json
import os
import signal
import subprocess
import time

import pytest

from conftest import ROOT
from test_multihost import PY, cluster, events, lines, statuses, wait_for  # noqa: F401

pytestmark = [pytest.mark.ros, pytest.mark.slow]
LIB = ("actions:\n  stop: {plugin: publish, topic: /safety_cmd, type: geometry_msgs/Twist, message: {}, "
       "rate: 20 Hz}\n")  # not latched: a stop that reads false or unknown for an instant is released
# 5 %: a hog starved by a loaded machine still reads above it, so the stop is never released by load alone
RULES = 'import "lib.yaml";\naction primitive stop;\n' + \
    "entity arm: hog { rules: busy: (cpu(node hog) > 5 %) for 1 s; }\nif (arm.busy) then { stop; }\n"
AGENT = os.path.join(ROOT, "scripts", "agent")
FAKE = """import json, sys, time
import rospy
from std_msgs.msg import String
rospy.init_node("g")
host = sys.argv[1]
pub = rospy.Publisher("/rubass/agent_samples", String, queue_size=10)
time.sleep(1.5)
def send(nodes, **extra):
    pub.publish(String(data=json.dumps(dict({"agent": "/g", "host": host, "period": 0.1, "time": 0,
                                             "nodes": nodes}, **extra))))
for nodes in ([{"node": "/hog", "alive": True, "cpu": -7, "memory": -1}], []):
    for i in range(30):
        send(nodes)
        time.sleep(0.1)
send([], leaving=True)
time.sleep(0.5)
print("fake done", flush=True)
"""


def write_spec(tmp_path):
    (tmp_path / "lib.yaml").write_text(LIB)
    (tmp_path / "safety.rbs").write_text(RULES)
    return str(tmp_path / "safety.rbs")


def start_on_arm(cluster, spec, *extra_agents):
    """The hog and its agents on `arm` at 4 Hz (silent only after 0.75 s: a loaded machine's
    hiccups do not make them so), the monitor and its listener on `safety`."""
    for name in ("",) + extra_agents:
        cluster.spawn("arm", [PY, AGENT, "_node_rate:=4"] + ([f"__name:={name}"] if name else []),
                      f"agent-{name or 'arm'}")
    cluster.node("arm", "hog", "hog")
    watch = cluster.listen("safety", "watch", "/diagnostics:diagnostic_msgs/DiagnosticArray",
                           "/rubass/events:std_msgs/String", "/rubass/node_samples:std_msgs/String")
    cluster.monitor(spec)
    return watch


def test_a_fake_report_for_the_hogs_host_is_not_used_and_the_status_names_both_agents(cluster, tmp_path):
    spec = write_spec(tmp_path)
    cluster.listen("arm", "arm_listener", "/safety_cmd:geometry_msgs/Twist")  # the stop reaches someone
    watch = start_on_arm(cluster, spec)
    wait_for(cluster, "the stop started", lambda: [e for e in events(watch) if e["event"] == "start"], timeout=40)
    arm = cluster.net.address["arm"]
    begun = time.time()
    fake = cluster.spawn("safety", [PY, "-c", FAKE, arm], "fake")
    assert fake.wait(40) == 0, cluster.log(fake)
    done = time.time()
    time.sleep(1.5)
    used = [json.loads(r["msg"]["data"]) for r in lines(watch)
            if r["topic"] == "/rubass/node_samples" and begun < r["wall"] < done]
    cpus = [u["cpu"] for u in used if u["node"] == "hog"]
    assert len(cpus) > 20 and all(c is None or c >= 0 for c in cpus), cpus  # never the fake's -7
    assert len([c for c in cpus if c is None]) <= 6, cpus  # the report without /hog made it unknown most of the time
    monitor = statuses(watch, "rubass: monitor")
    agent = f"/rubass_agent_{arm.replace('.', '_')}"
    assert any(f"agents /g and {agent} both report host {arm}" in m for _, m, _ in monitor), cluster.logs()
    assert not any("/g on" in m for _, m, _ in monitor), "the fake left: never reported silent"
    assert any("both report" in m for w, m, _ in monitor if w < done) and \
        not any("both report" in m for w, m, _ in monitor if w > done + 1.0)
    log = cluster.log(next(p for p in cluster.procs if p.log_path.name == "monitor.log"))
    assert "ignoring 1 entry of a report on /rubass/agent_samples" in log and "node /hog" in log


def test_a_second_agent_killed_on_the_hogs_host_replays_as_it_ran(cluster, tmp_path):
    spec = write_spec(tmp_path)
    cluster.listen("arm", "arm_listener", "/safety_cmd:geometry_msgs/Twist")  # the stop reaches someone
    bag = tmp_path / "run.bag"  # the agents' reports only: replay must use them as the monitor did
    recorder = cluster.spawn("safety", ["rosbag", "record", "-O", str(bag), "/rubass/agent_samples"], "record")
    watch = start_on_arm(cluster, spec, "extra")
    extra = next(p for p in cluster.procs if p.log_path.name == "agent-extra.log")
    wait_for(cluster, "the stop started", lambda: [e for e in events(watch) if e["event"] == "start"], timeout=40)
    os.killpg(extra.pid, signal.SIGKILL)
    time.sleep(3.0)
    os.killpg(recorder.pid, signal.SIGINT)  # rosbag and its recorder child write a complete bag on SIGINT
    assert recorder.wait(20) == 0, cluster.log(recorder)
    live = [e["event"] for e in events(watch) if e["event"] in ("start", "release")]
    assert live == ["start"], cluster.logs()
    out = subprocess.run([PY, "-m", "rubass", "replay", spec, str(bag), "--json"], cwd=ROOT, capture_output=True,
                         text=True, timeout=120, env=dict(os.environ, PYTHONPATH=ROOT))
    assert out.returncode == 0, out.stderr
    replayed = [json.loads(line) for line in out.stdout.splitlines()]
    assert [x["event"] for x in replayed if x["event"] in ("start", "release")] == ["start"], out.stdout
