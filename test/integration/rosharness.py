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
        from rubass.ros.master import PrivateMaster

        self.tmp = tmp_path
        self.master = PrivateMaster(str(tmp_path / "ros_home"))
        self.port = self.master.port
        self.env = dict(self.master.env, ROS_LOG_DIR=str(tmp_path / "ros_log"), PYTHONUNBUFFERED="1")
        self.procs = []

    def spawn(self, cmd, name, **kw):
        log = open(self.tmp / f"{name}.log", "w")
        proc = subprocess.Popen(cmd, env=self.env, stdout=kw.pop("stdout", log), stderr=subprocess.STDOUT,
                                cwd=str(self.tmp), start_new_session=True, **kw)
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
        from rubass.ros.master import stop_processes

        stop_processes(list(reversed(self.procs)))
        self.master.stop()
