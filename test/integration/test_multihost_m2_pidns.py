"""Issue 18: a node in its own PID namespace (`unshare --pid --fork --mount-proc`, as in a
container) answers getPid with 1; the monitor and the agent must not measure this machine's
pid 1 as that node, but read its cpu and memory unknown and say why."""
import json
import os
import subprocess

import pytest

from conftest import ROOT

pytestmark = [pytest.mark.ros, pytest.mark.slow]
PY = "/usr/bin/python3"
NODE = os.path.join(ROOT, "test", "integration", "multihost_node.py")
LIB = "actions:\n  stop: {plugin: publish, topic: /safety_cmd, type: geometry_msgs/Twist, message: {}, rate: 20 Hz}\n"
SPEC = ('import "lib.yaml";\naction primitive stop;\n'
        "entity arm: hog { rules: busy: (cpu(node hog) > 20 %) for 1 s; }\nif (arm.busy) then { stop; }\n")
REASON = "pid 1 that /hog reports does not listen on its port"


def unshare_works():
    try:
        out = subprocess.run(["unshare", "--pid", "--fork", "--mount-proc", "sh", "-c", "echo $$"],
                             capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return f"cannot run unshare: {exc}"
    if out.returncode != 0 or out.stdout.strip() != "1":
        return f"unshare --pid --fork --mount-proc fails here: {out.stderr.strip() or out.stdout.strip()}"
    return ""


def test_a_node_in_another_pid_namespace_reads_unknown_with_the_reason(ros, tmp_path):
    why = unshare_works()
    if why:
        pytest.skip(f"needs PID namespaces (root): {why}")
    (tmp_path / "lib.yaml").write_text(LIB)
    (tmp_path / "s.rbs").write_text(SPEC)
    hog = ros.spawn(["unshare", "--pid", "--fork", "--mount-proc", PY, NODE, "hog", "__name:=hog"], "hog")
    ros.spawn([PY, os.path.join(ROOT, "scripts", "agent"), "_node_rate:=10", "_discover_rate:=5"], "agent")
    mon = ros.monitor(str(tmp_path / "s.rbs"), diagnostics_rate=5)
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"},
                                {"topic": "/rubass/agent_samples", "type": "std_msgs/String"}],
                     "steps": [{"wait": "/rubass/agent_samples", "timeout": 30}, {"sleep": 4.0}]})
    logs = "\n".join(f"--- {p.log_path.name}\n{ros.log(p)[-1500:]}" for p in (hog, mon))
    becauses = [kv["value"] for r in rec if r["kind"] == "recv" and r["topic"] == "/diagnostics"
                for st in r["msg"]["status"] if st["name"] == "rubass: arm"
                for kv in st["values"] if kv["key"] == "busy unknown because"]
    assert becauses and REASON in becauses[-1] and "another PID namespace" in becauses[-1], logs
    entries = [n for r in rec if r["kind"] == "recv" and r["topic"] == "/rubass/agent_samples"
               for n in json.loads(r["msg"]["data"])["nodes"] if n["node"] == "/hog"]
    assert entries, logs
    last = entries[-1]
    assert last["pid"] == 1 and last["alive"] is True and last["cpu"] is None and last["memory"] is None
    assert REASON in last["why"]
