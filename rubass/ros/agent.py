"""The rubass agent: samples the nodes of its own host for a monitor on another host.

One agent runs on each computer of a robot (`rosrun rubass agent`, or launch/agent.launch in
the host's bringup). At every period it reads, for each node whose XML-RPC URI is on this
host, whether it answers (getPid, with a timeout), its CPU share and its memory (psutil and
/proc, as the monitor does for its own host), and publishes them all in one report. The
monitor uses these reports for the nodes on hosts other than its own (docs/multihost.md).
A report never waits for a slow node (each node is sampled by a task of its own). The nodes
discovered are kept in $ROS_HOME/rubass/agent_<host>.json (agent_cache.py), so that an agent
restarted after a master restart still knows the nodes that kept running.

ROS API
-------
Parameters (private)
    ~node_rate (Hz, default 10)      reports per second; give the monitor's ~node_rate
    ~discover_rate (Hz, default 1)   how often the master's node list is read for new nodes
Publishes
    /rubass/agent_samples (std_msgs/String)  one JSON report per period (rubass/ros/agentbook.py),
                                     sent even when the host runs no node: it is the agent's heartbeat;
                                     on a clean exit one last report with "leaving": true
Signals
    SIGINT/SIGTERM stop it (exit 0, within EXIT_GRACE seconds even with the master unreachable)
A bad parameter: the agent stays up without reporting, logging the error (FATAL, then ERROR every
60 s), and exits 1 when stopped (a respawning launch file would otherwise restart it for good).
"""
from __future__ import annotations

import concurrent.futures
import os
import re
import signal
import socket
import sys
import threading
import time
import xmlrpc.client
from typing import Any, Callable, Dict, List, Optional, Set, Tuple
from urllib.parse import urlparse

import psutil

from ..engine.values import UNKNOWN
from ..lang.errors import counted
from . import agent_cache, rpc
from .agentbook import AGENT_TOPIC, STALE_PERIODS, encode, is_loopback, node_entry
from .nodes import NodeSampler, NodeStatus
from .params import ParamError, read_rate, unknown_params
from .exiting import exit_within
from .startup import MasterLost, init_node, private_param, stop_asked, wants_help

Log = Callable[[str, str], None]
SAMPLE_WAIT = 0.5  # periods: how long a report waits for the samples it started (a hung node's never ends in time)


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
    """Discovers the nodes on this host and samples them; `step()` returns one report.

    Each node is sampled by a pending task of its own and a report never waits for a slow one:
    it carries each node's latest completed sample. A node whose sample has been under way longer
    than the monitor accepts a report (STALE_PERIODS periods) beyond the getPid timeout reads
    unknown, with why: within the timeout a slow answer is a busy node (a CPU hog answers late),
    and a node that does not answer by then is read alive false by its own sample. No second
    sample of a node starts while one is under way."""

    def __init__(self, name: str, host: str, master_uri: str, period: float, log: Log, timeout: float = 0.1,
                 cache_file: Optional[str] = None) -> None:
        self.name, self.host, self.master_uri, self.period, self.log = name, host, master_uri, period, log
        self.sampler = HostSampler([], lambda *a: None, time.time, period, name, timeout)
        self.sampler.master_uri = master_uri
        self.addresses = sorted(set(host_addresses() + ([host] if host and not is_loopback(host) else [])))
        self.seq = 0
        self.cache_file = cache_file
        self._saved: Optional[Dict[str, str]] = None  # what the cache file holds, as last written or read
        self._lock = threading.Lock()
        # threads are made only as samples need them: many hung nodes must not queue the healthy ones
        self._pool = concurrent.futures.ThreadPoolExecutor(max_workers=64, thread_name_prefix="rubass-agent")
        self._under_way: Dict[str, Tuple["concurrent.futures.Future[None]", float]] = {}  # node -> (task, started)
        self._latest: Dict[str, Tuple[float, Any, Any, Any, Optional[int], str]] = {}  # node -> last sample

    def load_cache(self) -> int:
        """Take the nodes of this host kept in the cache file by an earlier run, those that still answer
        getName with their name at their URI (a hung one is kept); how many."""
        if not self.cache_file:
            return 0
        try:
            cached = agent_cache.load(self.cache_file)
        except ValueError as exc:
            self.log("warn", f"rubass agent: ignoring the node cache: {exc}")
            return 0
        self._saved = dict(cached)
        entries = [(n, u) for n, u in cached.items()
                   if n != self.name and self.sampler._is_local(urlparse(u).hostname or "")]
        answers = list(self._pool.map(lambda e: agent_cache.check(e[0], e[1], self.name, self.sampler.timeout),
                                      entries))
        kept = [e for e, ok in zip(entries, answers) if ok is not False]
        with self._lock:
            for name, uri in kept:
                self.sampler._uris[name] = uri
                self.sampler.status.setdefault(name, NodeStatus(name, name))
        if kept:
            self.log("info", f"rubass agent: {counted(len(kept), 'node')} known from {self.cache_file} still answer: "
                             + ", ".join(n for n, _ in kept))
        self._save_cache()
        return len(kept)

    def discover(self, stop: Optional[threading.Event] = None) -> None:
        """Add the registered nodes whose URI is on this host; forget those the master does not know
        that no longer answer getName with their name at their URI (the master keeps a killed node's
        registrations; a restarted master knows only the nodes started since). `stop` set: no
        further question to a master that may have stopped answering half-way."""
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
            if stop is not None and stop.is_set():
                return
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
            unlisted = [(n, self.sampler._uris.get(n, "")) for n in self.sampler.status if n not in names]
        for name, uri in unlisted:
            if not uri or agent_cache.check(name, uri, self.name, self.sampler.timeout) is False:
                with self._lock:
                    self.sampler.status.pop(name, None)
        self._save_cache()

    def _save_cache(self) -> None:
        if not self.cache_file:
            return
        with self._lock:
            known = {n: self.sampler._uris[n] for n in self.sampler.status if n in self.sampler._uris and n != self.name}
        if known == self._saved:
            return
        try:
            agent_cache.save(self.cache_file, known)
        except OSError as exc:
            self.log("warn", f"rubass agent: cannot write the node cache {self.cache_file}: {exc} (a restart after "
                             f"a master restart will not know the nodes started before it)")
        self._saved = known

    def discover_every(self, period: float, stop: threading.Event) -> None:
        """discover() every `period` seconds until `stop` is set (on a thread of its own)."""
        while not stop.wait(period):
            try:
                self.discover(stop)
            except Exception as exc:  # never let discovery die: log and try again
                self.log("error", f"rubass agent: discovery failed: {exc.__class__.__name__}: {exc}")

    def _sample(self, st: NodeStatus, now: float) -> None:
        """One node's sample, on a pool thread; kept as the node's latest."""
        try:
            self.sampler.sample(st)
            latest = (now, st.alive, st.cpu, st.memory, st.pid, st.why)
        except Exception as exc:  # a bad node must not stop the reports of the others
            latest = (now, UNKNOWN, UNKNOWN, UNKNOWN, None, f"sampling failed: {exc.__class__.__name__}: {exc}")
        with self._lock:
            self._latest[st.resolved] = latest

    def step(self, now: float) -> str:
        """Start a sample of every node whose last one is done, wait for them up to half a period,
        and return the report's JSON with each node's latest completed sample."""
        with self._lock:
            statuses = list(self.sampler.status.values())
        started = []
        t0 = time.monotonic()
        for st in statuses:
            task = self._under_way.get(st.resolved)
            if task is None or task[0].done():
                future = self._pool.submit(self._sample, st, now)
                self._under_way[st.resolved] = (future, t0)
                started.append(future)
        if started:
            concurrent.futures.wait(started, timeout=SAMPLE_WAIT * self.period)
        at, limit = time.monotonic(), STALE_PERIODS * self.period + self.sampler.timeout
        uris = self.sampler._uris
        with self._lock:
            latest = dict(self._latest)
        nodes = []
        for st in statuses:
            name, uri = st.resolved, uris.get(st.resolved, "")
            future, since = self._under_way[name]
            last = latest.get(name)
            if not future.done() and at - since > limit:
                nodes.append(node_entry(name, now, UNKNOWN, UNKNOWN, UNKNOWN, None, uri,
                                        f"no answer from the node for {at - since:.2f} s (hung?)"))
            elif last is None:
                nodes.append(node_entry(name, now, UNKNOWN, UNKNOWN, UNKNOWN, None, uri, "not sampled yet"))
            else:
                nodes.append(node_entry(name, last[0], last[1], last[2], last[3], last[4], uri, last[5]))
        self._forget({st.resolved for st in statuses})
        self.seq += 1
        return encode(self.name, self.host, self.addresses, now, self.period, self.seq, nodes)

    def _forget(self, names: Set[str]) -> None:
        """Drop the tasks and samples of nodes discovery has dropped (once their sample is done)."""
        for name in [n for n, (f, _) in self._under_way.items() if n not in names and f.done()]:
            del self._under_way[name]
            with self._lock:
                self._latest.pop(name, None)

    def leaving(self, now: float) -> str:
        """The last report: the agent is leaving (a clean exit), so that the monitor forgets it rather
        than report it silent: "leaving": true, and no nodes."""
        self.seq += 1
        return encode(self.name, self.host, self.addresses, now, self.period, self.seq, [], leaving=True)

    def close(self) -> None:
        self._pool.shutdown(wait=True)  # the samples under way end within their timeouts
        self.sampler._release()


AGENT_PARAMS = ("node_rate", "discover_rate")  # what main() reads
USAGE = ("usage: rosrun rubass agent [_node_rate:=HZ] [_discover_rate:=HZ]\n"
         "Samples alive, CPU and memory of the nodes on this host at node_rate (default 10 Hz) and publishes\n"
         f"them on {AGENT_TOPIC} for a rubass monitor on another host; asks the master for the node list at\n"
         "discover_rate (default 1 Hz). See docs/multihost.md.\n")
UNREACHABLE = ("the nodes of this host keep being reported to the monitors already connected; the node list is "
               "not updated until the master is back")
BAD_PARAM_REPEAT = 60.0  # s: how often an agent that cannot start says so again
LEAVING_FLUSH = 0.2  # s: for the leaving report to leave the publisher's queue before rospy closes connections
EXIT_GRACE = 3.0  # s: the leaving report, the master watch's stop and rospy's shutdown, then the process exits
AGENT_DONE = "the agent had already stopped reporting"  # what exit_within says had been done


def main(argv: Optional[List[str]] = None) -> int:
    import rospy

    from .rosout_param import keep_rosout_flag

    if wants_help(argv):
        sys.stdout.write(USAGE)
        return 0
    code = init_node(default_name(), argv, lambda text: sys.stderr.write(f"rubass agent: {text}\n"))
    if code is not None:
        return code
    stop = threading.Event()
    # our own SIGINT/SIGTERM: rospy's runs its shutdown on the main thread, which then waits for
    # good to unregister from a master that does not answer (a cut link), and never leaves the loop
    def on_stop_signal(signum: int, frame: object) -> None:
        stop.set()  # and should the agent never get to stop (a master that hangs while it reads its
        exit_within(EXIT_GRACE + 1.0, 0, AGENT_DONE, "the agent did not stop")  # parameters): cut

    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, on_stop_signal)
    if stop_asked():  # one came between init_node and the lines above
        stop.set()
    keep_rosout_flag()  # no log call asks the master anything (one would block while its host is cut off)
    try:
        names = rospy.get_param_names()
    except Exception:  # noqa: BLE001 - only the warnings below are lost
        names = []
    for warning in unknown_params(names, rospy.get_name(), AGENT_PARAMS):  # a typo must not pass silently
        rospy.logwarn("rubass agent: %s", warning)
    try:
        rate = read_rate(private_param, "node_rate", 10.0, 0.1, 100.0)
        discover_period = 1.0 / read_rate(private_param, "discover_rate", 1.0, 0.01, 100.0)
    except ParamError as exc:
        code = _refuse(str(exc), stop)
        exit_within(EXIT_GRACE, code, AGENT_DONE)
    except MasterLost as exc:  # as when it goes away during init_node: one line, exit 1
        rospy.logfatal(f"rubass agent: cannot start: {exc}; nothing was reported")
        code = 1
        exit_within(EXIT_GRACE, code, AGENT_DONE)
    else:
        code = _run(rate, discover_period, stop)
    rospy.signal_shutdown("rubass agent stopped")  # unregisters: may wait for the master, cut above
    return code


def _refuse(error: str, stop: threading.Event) -> int:
    """A bad parameter: stay up without reporting, saying why now and every BAD_PARAM_REPEAT seconds
    (exiting would make a respawning launch file restart the agent into the same error, for good)."""
    import rospy

    rospy.core.add_preshutdown_hook(lambda reason: stop.set())
    text = (f"rubass agent: cannot start: {error}; reporting nothing (the monitor reads this host's cpu and memory "
            f"unknown) until the agent is restarted with a good value")
    rospy.logfatal(text)
    while not stop.wait(BAD_PARAM_REPEAT) and not rospy.is_shutdown():
        rospy.logerr(text)
    return 1


def _run(rate: float, discover_period: float, stop: threading.Event) -> int:
    """Report every period until `stop` is set or rospy shuts down; then the leaving report."""
    import rosgraph
    import rospy
    from std_msgs.msg import String

    from .master_watch import MasterWatch

    log: Log = lambda level, text: {"debug": rospy.logdebug, "info": rospy.loginfo,  # noqa: E731
                                    "warn": rospy.logwarn, "error": rospy.logerr}[level](text)
    host = urlparse(rospy.core.get_node_uri() or "").hostname or socket.gethostname()
    cache = agent_cache.cache_path(os.environ.get("ROS_HOME"), default_name()[len("rubass_agent_"):])
    agent = Agent(rospy.get_name(), host, rosgraph.get_master_uri(), 1.0 / rate, log, cache_file=cache)
    pub = rospy.Publisher(AGENT_TOPIC, String, queue_size=10, tcp_nodelay=True)
    watch = MasterWatch(rospy.get_name(), rospy.core.get_node_uri(), rosgraph.get_master_uri(), 0.5, log,
                        unreachable=UNREACHABLE)
    watch.start()
    sending = threading.Lock()
    left: List[bool] = []

    def leave(reason: str = "") -> None:
        """Once, before rospy unregisters: the leaving report, then the watch stopped (else it would
        find this node gone from the master and register it again)."""
        stop.set()
        with sending:
            if left:
                return
            left.append(True)
            if "new node registered with same name" in reason:  # the master's words: another agent is us now
                rospy.logwarn("rubass agent: another node took this agent's name: it reports from now on "
                              "(no leaving report, which would make the monitor drop it)")
                watch.stop()
                return
            try:
                pub.publish(String(data=agent.leaving(rospy.get_rostime().to_sec())))
                time.sleep(LEAVING_FLUSH)
            except Exception as exc:  # noqa: BLE001 - best effort: the monitor then reports the agent silent
                rospy.logwarn(f"rubass agent: the leaving report could not be sent: {exc}")
        watch.stop()

    rospy.core.add_preshutdown_hook(leave)  # rospy shutting down on its own (another node took the name)
    rospy.loginfo("rubass agent %s: reporting the nodes on host %s (%s) at %g Hz on %s", rospy.get_name(), host,
                  ", ".join(agent.addresses) or "no address", rate, AGENT_TOPIC)
    agent.load_cache()
    agent.discover(stop)
    threading.Thread(target=agent.discover_every, args=(discover_period, stop), name="rubass-discover",
                     daemon=True).start()  # a slow or hung master must not delay the reports
    next_at = time.monotonic()
    while not stop.is_set() and not rospy.is_shutdown():
        try:
            report = agent.step(rospy.get_rostime().to_sec())
            with sending:
                if not left:
                    pub.publish(String(data=report))
        except Exception as exc:  # a bad node must not stop the reports of the others
            rospy.logerr_throttle(10, f"rubass agent: sampling failed: {exc.__class__.__name__}: {exc}")
        next_at += agent.period
        delay = next_at - time.monotonic()
        if delay < 0:
            next_at = time.monotonic()
        stop.wait(max(0.0, delay))
    exit_within(EXIT_GRACE, 0, AGENT_DONE)  # from now: the watch's stop and rospy's unregistering may wait for the master
    leave()
    agent.close()
    return 0
