"""A private rosmaster on a free port, for the experiment runner and the benchmarks."""
from __future__ import annotations

import os
import signal
import socket
import subprocess
import time
import uuid
from typing import Dict, List, Optional

from rubass.ros.startup import master_answers

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))  # the checkout


class PrivateMaster:
    """`rosmaster --core` on a free loopback port; `env` is what every process started for it gets."""

    def __init__(self, home: str) -> None:
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            self.port = s.getsockname()[1]
        self.uri = f"http://127.0.0.1:{self.port}"
        os.makedirs(home, exist_ok=True)
        self.env: Dict[str, str] = dict(os.environ, ROS_MASTER_URI=self.uri, ROS_IP="127.0.0.1", ROS_HOME=home,
                                        PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""),
                                        PYTHONDONTWRITEBYTECODE="1")
        self.env.pop("ROS_HOSTNAME", None)
        self._start()

    def _start(self) -> None:
        self.process = subprocess.Popen(["rosmaster", "--core", "-p", str(self.port)], env=self.env,
                                        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        import rosgraph

        try:
            end = time.time() + 10
            while not master_answers(self.uri):  # not rosgraph's: it swallows a Ctrl-C raised inside it
                if time.time() > end or self.process.poll() is not None:
                    raise RuntimeError(f"rosmaster did not start on port {self.port}")
                time.sleep(0.05)
            self.online_at = time.time()  # when it first answered
            # roscore sets /run_id, and roslaunch waits for it; a bare rosmaster does not
            rosgraph.Master("/rubass", master_uri=self.uri).setParam("/run_id", str(uuid.uuid1()))
        except BaseException:  # a failed start, or a stop signal meanwhile: the caller never gets this master
            self.stop()
            raise

    def restart(self, down: float = 0.0) -> None:
        """Kill the master (SIGKILL, as a crash would), wait `down` seconds, start a new one on
        the same port: it knows no node, topic or parameter."""
        stop_processes([self.process], signal.SIGKILL)
        time.sleep(down)
        self._start()

    def join(self) -> None:
        """Make this process a client of the master (before rospy.init_node)."""
        os.environ.update({k: self.env[k] for k in ("ROS_MASTER_URI", "ROS_IP", "ROS_HOME")})

    def spawn(self, args: List[str], log: Optional[str] = None, cwd: Optional[str] = None) -> subprocess.Popen:
        out = open(log, "w") if log else subprocess.DEVNULL
        return subprocess.Popen(args, env=self.env, stdout=out, stderr=subprocess.STDOUT, cwd=cwd,
                                start_new_session=True)

    def stop(self) -> None:
        stop_processes([self.process])


def stop_processes(procs: List[subprocess.Popen], sig: int = signal.SIGTERM, timeout: float = 5.0) -> None:
    """Signal each process group, then wait; SIGKILL what does not exit in time."""
    for p in procs:
        if p.poll() is None:
            try:
                os.killpg(p.pid, sig)
            except ProcessLookupError:
                pass
    for p in procs:
        try:
            p.wait(timeout)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait(timeout)


def wait_for_service(name: str, proc: subprocess.Popen, uri: str, timeout: float) -> None:
    """Until a service is registered; RuntimeError if the process exits or time runs out."""
    import rosgraph

    master = rosgraph.Master("/rubass_wait", master_uri=uri)
    end = time.time() + timeout
    while True:
        if proc.poll() is not None:
            raise RuntimeError(f"the process exited with {proc.returncode} before {name} came up")
        try:
            master.lookupService(name)
            return
        except rosgraph.MasterError:
            if time.time() > end:
                raise RuntimeError(f"{name} did not come up within {timeout:g} s") from None
            time.sleep(0.05)
