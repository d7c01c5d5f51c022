"""A robot with several computers, for real: network namespaces as hosts (netns.py).

Hosts: `robot` (the master and the base's driver), `arm` (a second robot computer) and
`safety` (the monitor, on its own host as the paper proposes); an agent on each. Needs root
and iproute2; skipped with the reason otherwise.
"""
import json
import os
import signal
import subprocess
import time

import pytest

from conftest import ROOT

pytestmark = [pytest.mark.ros, pytest.mark.slow]

PY = "/usr/bin/python3"
NODE = os.path.join(ROOT, "test", "integration", "multihost_node.py")
LIB = """actions:
  stop: {plugin: publish, topic: /safety_cmd, type: geometry_msgs/Twist, message: {}, rate: 20 Hz, latch: true}
  warn: {plugin: log, level: warn}
"""
HOSTS = ["robot", "arm", "safety"]


class Cluster:
    """Processes on the hosts of a Network, with the master on `robot`."""

    def __init__(self, net, tmp):
        self.net, self.tmp, self.procs = net, tmp, []
        self.master_uri = f"http://{net.address['robot']}:11311"

    def env(self, host):
        env = dict(os.environ, ROS_MASTER_URI=self.master_uri, ROS_IP=self.net.address[host],
                   ROS_HOME=str(self.tmp / f"home-{host}"), ROS_LOG_DIR=str(self.tmp / f"log-{host}"),
                   PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""), PYTHONUNBUFFERED="1",
                   PYTHONDONTWRITEBYTECODE="1")
        env.pop("ROS_HOSTNAME", None)
        return env

    def spawn(self, host, args, name):
        log = self.tmp / f"{name}.log"
        proc = subprocess.Popen(self.net.cmd(host, args), env=self.env(host), stdout=open(log, "w"),
                                stderr=subprocess.STDOUT, cwd=str(self.tmp), start_new_session=True)
        proc.log_path = log
        self.procs.append(proc)
        return proc

    def run(self, host, code, timeout=30):
        """Python code run on `host` to completion (e.g. to wait for something there)."""
        return subprocess.run(self.net.cmd(host, [PY, "-c", code]), env=self.env(host), capture_output=True,
                              text=True, timeout=timeout)

    def start_master(self):
        self.spawn("robot", ["rosmaster", "--core", "-p", "11311"], "master")
        out = self.run("robot", "import rosgraph, time\nend = time.time() + 15\n"
                                f"while not rosgraph.is_master_online('{self.master_uri}') and time.time() < end:\n"
                                "    time.sleep(0.05)\n"
                                f"assert rosgraph.is_master_online('{self.master_uri}'), 'master not online'\n")
        assert out.returncode == 0, out.stderr

    def agent(self, host):
        return self.spawn(host, [PY, os.path.join(ROOT, "scripts", "agent"), "_node_rate:=10"], f"agent-{host}")

    def node(self, host, name, *args):
        return self.spawn(host, [PY, NODE, *args, f"__name:={name}"], name)

    def monitor(self, spec):
        return self.spawn("safety", [PY, os.path.join(ROOT, "scripts", "monitor"), "__name:=rubass",
                                     f"_spec:={spec}", "_diagnostics_rate:=5"], "monitor")

    def listen(self, host, name, *topics):
        out = self.tmp / f"{name}.jsonl"
        out.touch()
        self.node(host, name, "listen", str(out), *topics)
        return out

    @staticmethod
    def log(proc):
        return open(proc.log_path).read() if os.path.exists(proc.log_path) else ""

    def logs(self):
        return "\n".join(f"--- {p.args[3:6]}\n{self.log(p)[-1500:]}" for p in self.procs)

    def stop(self):
        from rubass_experiments.master import stop_processes

        for host in list(self.net.cut_hosts):  # nodes unregister from the master as they stop
            self.net.mend(host)
        stop_processes(list(reversed(self.procs)))


@pytest.fixture
def cluster(tmp_path):
    if not os.path.exists("/usr/bin/rosmaster"):
        pytest.skip("ROS 1 is not installed (rosmaster)")
    from netns import Network

    why = Network.check()
    if why:
        pytest.skip(f"multi-host tests need network namespaces: {why}")
    net = Network(HOSTS)
    try:
        net.setup()  # removes what it made if it fails
    except RuntimeError as exc:
        pytest.skip(f"multi-host tests: cannot make the test network here: {exc}")

    def terminated(signum, frame):  # SIGTERM (CI's timeout) unwinds through the clean-up below
        raise KeyboardInterrupt(f"signal {signum}")

    previous = signal.signal(signal.SIGTERM, terminated)
    c = Cluster(net, tmp_path)
    try:
        c.start_master()
        yield c
    finally:
        try:
            c.stop()
        finally:
            net.close()
            signal.signal(signal.SIGTERM, previous)
    assert net.leftovers() == [], "namespaces left behind"


def write_spec(tmp_path, body):
    (tmp_path / "lib.yaml").write_text(LIB)
    path = tmp_path / "safety.rbs"
    path.write_text('import "lib.yaml";\naction primitive stop, warn;\n' + body)
    return str(path)


def lines(path):
    out = []
    for line in open(path).read().splitlines():
        try:
            out.append(json.loads(line))
        except ValueError:
            pass  # a line being written
    return out


def wait_for(cluster, what, test, timeout=30.0):
    end = time.time() + timeout
    while time.time() < end:
        found = test()
        if found:
            return found
        time.sleep(0.1)
    raise AssertionError(f"{what} within {timeout:g} s\n{cluster.logs()}")


def statuses(path, name):
    """Every /diagnostics status named `name`, oldest first: (wall, message, values)."""
    out = []
    for rec in lines(path):
        if rec["topic"] == "/diagnostics":
            for st in rec["msg"]["status"]:
                if st["name"] == name:
                    out.append((rec["wall"], st["message"], {kv["key"]: kv["value"] for kv in st["values"]}))
    return out


def events(path):
    return [dict(json.loads(r["msg"]["data"]), wall=r["wall"]) for r in lines(path) if r["topic"] == "/rubass/events"]


def start_everywhere(cluster, spec, *robot_nodes, watch=()):
    """Agents on every host, the robot's nodes, the monitor and its listener on `safety`."""
    for host in HOSTS:
        cluster.agent(host)
    for host, name, *args in robot_nodes:
        cluster.node(host, name, *args)
    watch = cluster.listen("safety", "watch", "/diagnostics:diagnostic_msgs/DiagnosticArray",
                           "/rubass/events:std_msgs/String", *watch)
    cluster.monitor(spec)
    return watch


def test_a_cpu_hog_on_another_host_is_measured_by_its_agent_and_stopped(cluster, tmp_path):
    spec = write_spec(tmp_path, "entity arm: hog { rules: busy: (cpu(node hog) > 20 %) for 1 s; }\n"
                                "if (arm.busy) then { stop; }\n")
    stops = cluster.listen("arm", "arm_listener", "/safety_cmd:geometry_msgs/Twist")
    bag = tmp_path / "run.bag"  # the agents' reports only: replay must use them
    recorder = cluster.spawn("safety", ["rosbag", "record", "-O", str(bag), "/rubass/agent_samples"], "record")
    watch = start_everywhere(cluster, spec, ("arm", "hog", "hog"))
    wait_for(cluster, "the stop reached the arm's host", lambda: lines(stops), timeout=40)
    start = wait_for(cluster, "a start event", lambda: [e for e in events(watch) if e["event"] == "start"])[0]
    assert start["rules"] == ["arm.busy"] and start["actions"] == ["stop"]
    assert start["cause"] in ("deadline", "node sample of /hog")  # the node as the robot names it
    time.sleep(0.5)
    os.killpg(recorder.pid, signal.SIGINT)  # rosbag and its recorder child write a complete bag on SIGINT
    assert recorder.wait(20) == 0, cluster.log(recorder)
    out = subprocess.run([PY, "-m", "rubass", "replay", spec, str(bag), "--json"], cwd=ROOT, capture_output=True,
                         text=True, timeout=120, env=dict(os.environ, PYTHONPATH=ROOT))
    assert out.returncode == 0, out.stderr
    replayed = [json.loads(line) for line in out.stdout.splitlines()]
    assert [x["actions"] for x in replayed if x["event"] == "start"] == [["stop"]], out.stdout + out.stderr


def test_agent_launch_reports_the_nodes_of_its_host(ros, tmp_path):
    """launch/agent.launch included from a host's bringup; no namespaces needed."""
    bringup = tmp_path / "bringup.launch"
    bringup.write_text('<launch>\n  <include file="$(find rubass)/launch/agent.launch">\n'
                       '    <arg name="node_rate" value="5"/>\n  </include>\n</launch>\n')
    ros.env["ROS_PACKAGE_PATH"] = ROOT + os.pathsep + ros.env.get("ROS_PACKAGE_PATH", "/usr/share")
    launch = ros.spawn(["roslaunch", "--wait", str(bringup)], "roslaunch")
    rec = ros.probe({"listen": [{"topic": "/rubass/agent_samples", "type": "std_msgs/String"}],
                     "steps": [{"wait": "/rubass/agent_samples", "timeout": 30}, {"sleep": 1.5}]})
    reports = [json.loads(r["msg"]["data"]) for r in rec if r["kind"] == "recv"]
    assert reports, ros.log(launch)
    last = reports[-1]
    assert last["agent"].startswith("/rubass_agent") and last["period"] == pytest.approx(0.2)
    assert any(last["agent"] in {n["node"] for n in r["nodes"]} for r in reports)  # itself, a node of this host
    launch.send_signal(signal.SIGINT)
    assert launch.wait(20) == 0


def test_an_agent_keeps_reporting_while_the_master_hangs(ros):
    agent = ros.spawn([PY, os.path.join(ROOT, "scripts", "agent"), "_node_rate:=10", "_discover_rate:=5"], "agent")
    probe = ros.probe_bg({"listen": [{"topic": "/rubass/agent_samples", "type": "std_msgs/String"}],
                          "steps": [{"wait": "/rubass/agent_samples", "timeout": 30}, {"sleep": 1.2},
                                    {"mark": "ready"}, {"sleep": 3.0}]})
    line = probe.stdout.readline()
    while line and '"ready"' not in line:
        line = probe.stdout.readline()
    assert '"ready"' in line, ros.log(agent)
    os.kill(ros.master.process.pid, signal.SIGSTOP)  # discovery now waits on the master (1 s timeouts)
    try:
        hung = time.time()
        time.sleep(2.6)
    finally:
        os.kill(ros.master.process.pid, signal.SIGCONT)
    out, _ = probe.communicate(timeout=30)
    during = [json.loads(x) for x in out.splitlines() if x.startswith("{")]
    during = [r for r in during if r["kind"] == "recv" and hung + 0.5 < r["wall"] < hung + 2.5]
    assert len(during) >= 10, f"{len(during)} reports in 2 s while the master hung\n{ros.log(agent)}"


def test_an_agent_with_a_bad_rate_says_which_parameter(ros):
    proc = ros.spawn([PY, os.path.join(ROOT, "scripts", "agent"), "_node_rate:=fast"], "agent-bad")
    from rosharness import wait_log

    wait_log(proc, ros, "cannot start", timeout=30)  # and stays up (docs/multihost.md): stopped, it exits 1
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(15) == 1
    log = ros.log(proc)
    assert "~node_rate must be a rate" in log and "'fast'" in log and "Traceback" not in log


def test_a_bad_report_is_ignored_and_the_monitor_goes_on(ros, tmp_path):
    spec = write_spec(tmp_path, "entity arm: calm { rules: busy: cpu(node calm) > 95 %; }\n")
    mon = ros.monitor(spec)
    ros.probe({"advertise": [{"topic": "/rubass/agent_samples", "type": "std_msgs/String"}],
               "steps": [{"wait_subscribers": "/rubass/agent_samples"}, {"sleep": 0.3},
                         {"publish": "/rubass/agent_samples", "msg": {"data": "{not json"}},
                         {"publish": "/rubass/agent_samples",
                          "msg": {"data": '{"agent": "/a", "period": -1, "nodes": []}'}},
                         {"sleep": 0.5}]})
    from rosharness import wait_log

    wait_log(mon, ros, "ignoring a bad report on /rubass/agent_samples: not JSON")
    assert mon.poll() is None and "Traceback" not in ros.log(mon)


def test_a_killed_agent_makes_its_hosts_rules_unknown_and_the_status_names_it(cluster, tmp_path):
    spec = write_spec(tmp_path, "entity arm: calm { rules: busy: cpu(node calm) > 95 %;\n"
                                "  down: not alive(node calm); }\n"
                                "if (arm.busy or arm.down) then { warn(\"arm\"); }\n")
    watch = start_everywhere(cluster, spec, ("arm", "calm", "talk", "/arm_state", "5"))
    wait_for(cluster, "arm's rule known (false) from its agent",
             lambda: [s for s in statuses(watch, "rubass: arm") if s[1] == "all rules false"], timeout=40)
    agent = next(p for p in cluster.procs if p.log_path.name == "agent-arm.log")
    os.killpg(agent.pid, signal.SIGKILL)
    killed = time.time()
    silent = wait_for(cluster, "the arm's rule unknown because its agent is silent",
                      lambda: [s for s in statuses(watch, "rubass: arm") if s[0] > killed and s[1] == "unknown: busy"])
    why = silent[-1][2]["busy unknown because"]
    assert silent[-1][2]["down"] == "false"  # alive() asks the node itself, not the agent
    arm = cluster.net.address["arm"]
    assert f"agent /rubass_agent_{arm.replace('.', '_')} on host {arm} is silent" in why, why
    mon = wait_for(cluster, "the monitor's status names the silent agent",
                   lambda: [s for s in statuses(watch, "rubass: monitor") if "agent silent" in s[1]])
    assert f"/rubass_agent_{arm.replace('.', '_')} on {arm}" in mon[-1][1]
    assert "/rubass_agent_10_200_0_1 on 10.200.0.1" in mon[-1][2]["agents"]  # every agent is listed


def test_a_cut_link_fires_the_age_and_alive_rules_as_written(cluster, tmp_path):
    spec = write_spec(tmp_path, "entity base: driver { rules: stale: age(topic /odom) > 1 s;\n"
                                "  gone: not alive(node driver); }\n"
                                "if (base.stale) then { warn(\"odometry stale\"); }\n"
                                "if (base.gone) then { warn(\"driver gone\"); }\n")
    beats = cluster.listen("robot", "board", "/rubass/heartbeat:std_msgs/Header")  # where a watchdog would be
    watch = start_everywhere(cluster, spec, ("robot", "driver", "talk", "/odom", "20"),
                             watch=["/odom:std_msgs/Header"])  # beside the monitor: when /odom last came
    wait_for(cluster, "the base's rules false",
             lambda: [s for s in statuses(watch, "rubass: base") if s[1] == "all rules false"], timeout=40)
    wait_for(cluster, "heartbeats on the robot's host", lambda: lines(beats))
    cluster.net.cut("robot")
    cut = time.time()
    started = wait_for(cluster, "both behaviours started",
                       lambda: (lambda ev: ev if {1, 2} <= {e["behaviour"] for e in ev} else None)(
                           [e for e in events(watch) if e["event"] == "start" and e["wall"] > cut]))
    first = {e["behaviour"]: e for e in reversed(started)}
    assert first[1]["rules"] == ["base.stale"] and first[2]["rules"] == ["base.gone"]
    # age > 1 s: no sooner than a second after the last /odom reached the monitor's host
    last_odom = max(r["wall"] for r in lines(watch) if r["topic"] == "/odom")
    assert first[1]["wall"] > last_odom + 0.95
    assert first[2]["wall"] - cut < 10
    # a watchdog on the robot's host hears no heartbeat after the cut (a beat in flight may land)
    assert all(b["wall"] < cut + 1.0 for b in lines(beats))
