"""Integration-test harness: a private rosmaster per test, the monitor and probes as processes."""
import json
import os
import subprocess
import time

import pytest

from conftest import ROOT

PROBE = os.path.join(ROOT, "test", "integration", "probe.py")
PY = "/usr/bin/python3"


class Ros:
    """A private master on a free port (rubass's own PrivateMaster) and the environment every
    process of the test gets."""

    def __init__(self, tmp_path):
        if not os.path.exists("/usr/bin/rosmaster"):
            pytest.skip("ROS 1 is not installed (rosmaster)")
        from rubass_experiments.master import PrivateMaster
        from rubass_experiments.procs import Supervisor

        self.tmp = tmp_path
        # every process of the test carries its marker (self.env): if pytest is killed (SIGTERM from a
        # CI timeout, SIGKILL) before stop(), the supervisor's reaper stops them (issue 19)
        self.sup = Supervisor(signals=False).__enter__()
        try:
            self.master = PrivateMaster(str(tmp_path / "ros_home"))
        except BaseException:
            self.sup.__exit__(None, None, None)
            raise
        self.sup.adopt(self.master.process)
        self.port = self.master.port
        self.env = dict(self.master.env, ROS_LOG_DIR=str(tmp_path / "ros_log"), PYTHONUNBUFFERED="1")
        self.procs = []

    def spawn(self, cmd, name, **kw):
        log = open(self.tmp / f"{name}.log", "w")
        proc = subprocess.Popen(cmd, env=kw.pop("env", self.env), stdout=kw.pop("stdout", log), stderr=subprocess.STDOUT,
                                cwd=kw.pop("cwd", str(self.tmp)), start_new_session=True, **kw)
        proc.log_path = self.tmp / f"{name}.log"
        self.procs.append(proc)
        return proc

    def monitor(self, spec, name="rubass", wait=True, **params):
        args = [PY, os.path.join(ROOT, "scripts", "monitor"), f"__name:={name}", f"_spec:={spec}"]
        args += [f"_{k}:={v}" for k, v in params.items()]
        proc = self.spawn(args, f"monitor-{name}")
        if wait:
            self.wait_service(f"/{name}/reset", proc)
        return proc

    def wait_service(self, service, proc=None, timeout=15.0):
        import rosgraph

        master = rosgraph.Master("/test", master_uri=f"http://127.0.0.1:{self.port}")
        end = time.time() + timeout
        while time.time() < end:
            if proc is not None and proc.poll() is not None:
                raise AssertionError(f"process exited {proc.returncode}:\n{self.log(proc)}")
            try:
                master.lookupService(service)
                return
            except rosgraph.MasterError:
                time.sleep(0.05)
        raise AssertionError(f"{service} never came up")

    def probe(self, plan, timeout=60):
        """Run a probe to completion; its records."""
        out = subprocess.run([PY, PROBE, json.dumps(plan)], env=self.env, capture_output=True, text=True,
                             timeout=timeout, cwd=str(self.tmp))
        assert out.returncode == 0, out.stderr
        return [json.loads(line) for line in out.stdout.splitlines() if line.startswith("{")]

    def probe_bg(self, plan, name="probe"):
        return self.spawn([PY, PROBE, json.dumps(plan)], name, stdout=subprocess.PIPE, text=True)

    def call(self, service, timeout=20):
        return subprocess.run(["rosservice", "call", service], env=self.env, capture_output=True, text=True,
                              timeout=timeout)

    @staticmethod
    def log(proc):
        return open(proc.log_path).read() if os.path.exists(proc.log_path) else ""

    def stop(self):
        from rubass_experiments.master import stop_processes

        try:
            stop_processes(list(reversed(self.procs)))
            self.master.stop()
        finally:
            self.sup.__exit__(None, None, None)


LIB = """actions:
  stop: {plugin: publish, topic: /safety_cmd, type: geometry_msgs/Twist, message: {}, rate: 20 Hz, latch: true}
  brake: {plugin: publish, topic: /brake, type: std_msgs/Bool, message: {data: true}, rate: 20 Hz}
  warn: {plugin: log, level: warn}
"""
TWIST = "geometry_msgs/Twist"


def spec(tmp_path, body, lib=LIB, name="s.rbs"):
    (tmp_path / "lib.yaml").write_text(lib)
    path = tmp_path / name
    path.write_text('import "lib.yaml";\naction primitive stop, brake, warn;\n' + body)
    return str(path)


def first(records, kind, topic):
    return next((r for r in records if r["kind"] == kind and r["topic"] == topic), None)


def listen_until_stopped(ros, topic, type_, name="listener", timeout=8):
    """A background probe that says 'ready' once the monitor's publisher is up, then waits."""
    proc = ros.probe_bg({"listen": [{"topic": topic, "type": type_}],
                         "steps": [{"wait_publishers": topic}, {"sleep": 0.3}, {"mark": "ready"},
                                   {"wait": topic, "timeout": timeout}], "linger": 0.1}, name=name)
    line = proc.stdout.readline()
    assert '"ready"' in line, line + ros.log(proc)
    return proc


def records(proc):
    import json

    out, _ = proc.communicate(timeout=30)
    return [json.loads(line) for line in out.splitlines() if line.startswith("{")]


def wait_log(proc, ros, text, timeout=10.0):
    end = time.time() + timeout
    while time.time() < end:
        if text in ros.log(proc):
            return True
        time.sleep(0.05)
    raise AssertionError(f"'{text}' never logged:\n{ros.log(proc)}")


def brake_after(ros, value, wait=1.0, grace=0.0):
    """Publish /cmd_vel linear.x = value; the /brake messages that follow within `wait`, from `grace`
    seconds after it (a brake that was on may send one more message, already under way, as it ends)."""
    rec = ros.probe({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}],
                     "advertise": [{"topic": "/cmd_vel", "type": TWIST}],
                     "steps": [{"wait_subscribers": "/cmd_vel"}, {"sleep": 0.3}, {"mark": "go"},
                               {"publish": "/cmd_vel", "msg": {"linear": {"x": value}}}, {"sleep": wait}]})
    go = next(r["wall"] for r in rec if r["kind"] == "mark")
    return [r for r in rec if r["kind"] == "recv" and r["wall"] > go + grace and r["msg"]["data"] is True]


def monitor_values(ros):
    """The key/values of the monitor's own /diagnostics status (`rubass: monitor`), its latest."""
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"wait": "/diagnostics", "timeout": 10}, {"sleep": 1.2}]})
    mons = [s for r in rec if r["kind"] == "recv" for s in r["msg"]["status"] if s["name"] == "rubass: monitor"]
    assert mons
    return {kv["key"]: kv["value"] for kv in mons[-1]["values"]}
