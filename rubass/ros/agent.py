"""The rubass agent: samples the nodes of its own host for a monitor on another host.

One agent runs on each computer of a robot (`rosrun rubass agent`, or launch/agent.launch in
the host's bringup). At every period it reads, for each node whose XML-RPC URI is on this
host, whether it answers (getPid, with a timeout), its CPU share and its memory (psutil and
/proc, as the monitor does for its own host), and publishes them all in one report. The
monitor uses these reports for the nodes on hosts other than its own (docs/multihost.md).

ROS API
-------
Parameters (private)
    ~node_rate (Hz, default 10)      reports per second; give the monitor's ~node_rate
    ~discover_rate (Hz, default 1)   how often the master's node list is read for new nodes
Publishes
    /rubass/agent_samples (std_msgs/String)  one JSON report per period (rubass/ros/agentbook.py),
                                     sent even when the host runs no node: it is the agent's heartbeat
Signals
    SIGINT/SIGTERM stop it (exit 0)
"""
from __future__ import annotations

import concurrent.futures
import os
import re
import socket
import sys
import threading
import time
import xmlrpc.client
from typing import Any, Callable, List, Optional, Set, Tuple
from urllib.parse import urlparse

import psutil

from ..engine.values import UNKNOWN
from . import rpc
from .agentbook import AGENT_TOPIC, encode, is_loopback, node_entry
from .nodes import NodeSampler, NodeStatus
from .params import ParamError, read_rate, unknown_params
from .startup import init_node, wants_help

Log = Callable[[str, str], None]


def host_addresses() -> List[str]:
    """This host's names and addresses, loopback left out (every host has those)."""
    names = {socket.gethostname(), socket.getfqdn()}
    for addrs in psutil.net_if_addrs().values():
        names.update(a.address for a in addrs if a.family in (socket.AF_INET, socket.AF_INET6))
    return sorted(n for n in names if n and not is_loopback(n))


def default_name() -> str:
    """rubass_agent_<host>, from ROS_HOSTNAME, ROS_IP or the host name: unique per host."""
    host = os.environ.get("ROS_HOSTNAME") or os.environ.get("ROS_IP") or socket.gethostname()
    return "rubass_agent_" + (re.sub(r"[^A-Za-z0-9_]", "_", host) or "host")


class HostSampler(NodeSampler):
    """The monitor's sampler, asking each node at the URI that discovery found rather than
    asking the master every period too (one lookup per node and discovery, not per sample)."""

    def _ask(self, st: NodeStatus) -> Tuple[Any, Optional[int], str]:
        uri = self._uris.get(st.resolved)
        if uri is None:
            return UNKNOWN, None, "not discovered yet"
        pid, why = self._pid_at(uri)
        return (False, None, why) if pid is None else (True, pid, "alive")


class Agent:
    """Discovers the nodes on this host and samples them; `step()` returns one report."""

    def __init__(self, name: str, host: str, master_uri: str, period: float, log: Log, timeout: float = 0.1) -> None:
        self.name, self.host, self.master_uri, self.period, self.log = name, host, master_uri, period, log
        self.sampler = HostSampler([], lambda *a: None, time.time, period, name, timeout)
        self.sampler.master_uri = master_uri
        self.addresses = sorted(set(host_addresses() + ([host] if host and not is_loopback(host) else [])))
        self.seq = 0
        self._lock = threading.Lock()
        self._pool = concurrent.futures.ThreadPoolExecutor(max_workers=8, thread_name_prefix="rubass-agent")

    def discover(self) -> None:
        """Add the registered nodes whose URI is on this host; forget those gone from the
        master that no longer answer (the master keeps a killed node's registrations)."""
        master = rpc.proxy(self.master_uri, 1.0)
        try:
            code, msg, state = master.getSystemState(self.name)
        except (OSError, xmlrpc.client.Error) as exc:
            self.log("debug", f"rubass agent: the master cannot be reached ({exc}); sampling the nodes known")
            return
        if code != 1:
            return
        names: Set[str] = {n for kind in state for _, nodes in kind for n in nodes}
        for name in sorted(names):
            try:
                code, _, uri = master.lookupNode(self.name, name)
            except (OSError, xmlrpc.client.Error):
                continue
            if code != 1:
                continue
            local = self.sampler._is_local(urlparse(uri).hostname or "")
            with self._lock:
                self.sampler._uris[name] = uri
                if local and name not in self.sampler.status:
                    self.sampler.status[name] = NodeStatus(name, name)
                elif not local:
                    self.sampler.status.pop(name, None)  # started again on another host
        with self._lock:
            for name, st in list(self.sampler.status.items()):
                if name not in names and st.alive is False:
                    del self.sampler.status[name]

    def discover_every(self, period: float, stop: threading.Event) -> None:
        """discover() every `period` seconds until `stop` is set (on a thread of its own)."""
        while not stop.wait(period):
            try:
                self.discover()
            except Exception as exc:  # never let discovery die: log and try again
                self.log("error", f"rubass agent: discovery failed: {exc.__class__.__name__}: {exc}")

    def step(self, now: float) -> str:
        """Sample every node of this host (in parallel) and return the report's JSON."""
        with self._lock:
            statuses = list(self.sampler.status.values())
        list(self._pool.map(self.sampler.sample, statuses))
        uris = self.sampler._uris
        nodes = [node_entry(st.resolved, now, st.alive, st.cpu, st.memory, st.pid, uris.get(st.resolved, ""), st.why)
                 for st in statuses]
        self.seq += 1
        return encode(self.name, self.host, self.addresses, now, self.period, self.seq, nodes)

    def close(self) -> None:
        self._pool.shutdown(wait=True)  # the samples under way end within their timeouts
        self.sampler._release()


AGENT_PARAMS = ("node_rate", "discover_rate")  # what main() reads
USAGE = ("usage: rosrun rubass agent [_node_rate:=HZ] [_discover_rate:=HZ]\n"
         "Samples alive, CPU and memory of the nodes on this host at node_rate (default 10 Hz) and publishes\n"
         f"them on {AGENT_TOPIC} for a rubass monitor on another host; asks the master for the node list at\n"
         "discover_rate (default 1 Hz). See docs/multihost.md.\n")


def main(argv: Optional[List[str]] = None) -> int:
    import rosgraph
    import rospy
    from std_msgs.msg import String

    from .master_watch import MasterWatch
    from .rosout_param import keep_rosout_flag

    if wants_help(argv):
        sys.stdout.write(USAGE)
        return 0
    code = init_node(default_name(), argv, True, lambda text: sys.stderr.write(f"rubass agent: {text}\n"))
    if code is not None:
        return code
    keep_rosout_flag()  # no log call asks the master anything (one would block while its host is cut off)
    log: Log = lambda level, text: {"debug": rospy.logdebug, "info": rospy.loginfo,  # noqa: E731
                                    "warn": rospy.logwarn, "error": rospy.logerr}[level](text)
    try:
        names = rospy.get_param_names()
    except Exception:  # noqa: BLE001 - only the warnings below are lost
        names = []
    for warning in unknown_params(names, rospy.get_name(), AGENT_PARAMS):  # a typo must not pass silently
        rospy.logwarn("rubass agent: %s", warning)
    try:
        get = lambda name, default: rospy.get_param("~" + name, default)  # noqa: E731
        rate = read_rate(get, "node_rate", 10.0, 0.1, 100.0)
        discover_period = 1.0 / read_rate(get, "discover_rate", 1.0, 0.01, 100.0)
    except ParamError as exc:
        rospy.logfatal("rubass agent: cannot start: %s", exc)  # rospy writes it to stderr: once
        return 1
    host = urlparse(rospy.core.get_node_uri() or "").hostname or socket.gethostname()
    agent = Agent(rospy.get_name(), host, rosgraph.get_master_uri(), 1.0 / rate, log)
    pub = rospy.Publisher(AGENT_TOPIC, String, queue_size=10, tcp_nodelay=True)
    watch = MasterWatch(rospy.get_name(), rospy.core.get_node_uri(), rosgraph.get_master_uri(), 0.5, log)
    watch.start()
    stop = threading.Event()
    rospy.on_shutdown(stop.set)
    rospy.loginfo("rubass agent %s: reporting the nodes on host %s (%s) at %g Hz on %s", rospy.get_name(), host,
                  ", ".join(agent.addresses) or "no address", rate, AGENT_TOPIC)
    agent.discover()
    threading.Thread(target=agent.discover_every, args=(discover_period, stop), name="rubass-discover",
                     daemon=True).start()  # a slow or hung master must not delay the reports
    next_at = time.monotonic()
    while not stop.is_set() and not rospy.is_shutdown():
        try:
            pub.publish(String(data=agent.step(rospy.get_rostime().to_sec())))
        except Exception as exc:  # a bad node must not stop the reports of the others
            rospy.logerr_throttle(10, f"rubass agent: sampling failed: {exc.__class__.__name__}: {exc}")
        next_at += agent.period
        delay = next_at - time.monotonic()
        if delay < 0:
            next_at = time.monotonic()
        stop.wait(max(0.0, delay))
    watch.stop()
    agent.close()
    return 0
