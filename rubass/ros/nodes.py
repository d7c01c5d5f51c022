"""Node liveness, CPU and memory, sampled on a thread of its own.

`alive` asks the node itself (XML-RPC getPid, with a timeout) rather than trusting the
master, which never forgets a dead node; a node hung with SIGSTOP still accepts connections,
so only the timeout finds it. CPU and memory come from psutil, for nodes on this host.
"""
from __future__ import annotations

import concurrent.futures
import math
import os
import socket
import threading
import time
import xmlrpc.client
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Optional, Set, Tuple
from urllib.parse import urlparse

import psutil
import rosgraph

from ..engine.values import UNKNOWN
from . import rpc
from .pidcheck import PortOwners

Submit = Callable[[str, float, Any, Any, Any], None]  # (spec node, ROS time, alive, cpu, memory)
Remote = Callable[[str, str, int], Tuple[Any, Any, str]]  # (resolved node, host, pid) -> (cpu, memory, why)


def _schedstat_seconds(pid: int) -> Optional[float]:
    """Run time of all the process's threads, in seconds, or None where /proc lacks schedstat."""
    total = 0
    try:
        for tid in os.listdir(f"/proc/{pid}/task"):
            try:
                with open(f"/proc/{pid}/task/{tid}/schedstat") as fh:
                    total += int(fh.read().split()[0])
            except (OSError, ValueError, IndexError):
                continue  # a thread that just exited
    except OSError:
        return None
    return total / 1e9


def _fd_budget() -> int:
    """How many /proc files the samplers may keep open: an eighth of the soft limit, at most 512,
    so that many nodes of many threads never starve the monitor of sockets (EMFILE)."""
    try:
        import resource

        soft = resource.getrlimit(resource.RLIMIT_NOFILE)[0]
        if soft == resource.RLIM_INFINITY:
            soft = 65536
    except (ImportError, ValueError, OSError):
        soft = 1024
    return max(0, min(512, soft // 8))


class _KeptFiles:
    """The budget of kept /proc files, shared by every RunTime of the process."""

    def __init__(self, budget: int) -> None:
        self.budget, self.held = budget, 0
        self.lock = threading.Lock()

    def take(self) -> bool:
        with self.lock:
            if self.held >= self.budget:
                return False
            self.held += 1
            return True

    def give_back(self) -> None:
        with self.lock:
            self.held -= 1


KEPT_FILES = _KeptFiles(_fd_budget())


class RunTime:
    """`_schedstat_seconds` of one process, with each thread's file kept open and read again
    with pread: a sample costs a directory listing and a read per thread, not an open too
    (about 6x less CPU for a rospy node's threads). Beyond the process's budget of kept files
    (KEPT_FILES), a thread's file is opened, read and closed at each sample, as before."""

    def __init__(self, pid: int) -> None:
        self.pid = pid
        self._fds: Dict[str, int] = {}

    def seconds(self) -> Optional[float]:
        try:
            tids = os.listdir(f"/proc/{self.pid}/task")
        except OSError:
            self.close()
            return None
        total = 0
        for tid in tids:
            fd = self._fds.get(tid)
            try:
                if fd is None:
                    path = f"/proc/{self.pid}/task/{tid}/schedstat"
                    if not KEPT_FILES.take():
                        with open(path, "rb") as fh:
                            total += int(fh.read().split()[0])
                        continue
                    try:
                        fd = self._fds[tid] = os.open(path, os.O_RDONLY)
                    except OSError:
                        KEPT_FILES.give_back()
                        raise
                total += int(os.pread(fd, 128, 0).split()[0])
            except (OSError, ValueError, IndexError):
                self._drop(tid)  # a thread that just exited
        if len(self._fds) > len(tids):
            for tid in set(self._fds) - set(tids):
                self._drop(tid)
        return total / 1e9

    def close(self) -> None:
        for tid in list(self._fds):
            self._drop(tid)

    def _drop(self, tid: str) -> None:
        fd = self._fds.pop(tid, None)
        if fd is not None:
            os.close(fd)
            KEPT_FILES.give_back()


@dataclass
class NodeStatus:
    spec_name: str
    resolved: str
    alive: Any = UNKNOWN
    cpu: Any = UNKNOWN
    memory: Any = UNKNOWN
    pid: Optional[int] = None
    why: str = "not sampled yet"


def _local_addresses() -> Set[str]:
    names = {"localhost", socket.gethostname(), socket.getfqdn()}
    for addrs in psutil.net_if_addrs().values():
        names.update(a.address for a in addrs)
    return names


class NodeSampler:
    LOOKUP_PERIOD = 1.0  # s: how long the master's answer for a node's URI is used without asking again
    def __init__(self, nodes: List[Tuple[str, str]], submit: Submit, now: Callable[[], float], period: float,
                 caller_id: str, timeout: float = 0.1) -> None:
        self.status: Dict[str, NodeStatus] = {r: NodeStatus(n, r) for n, r in nodes}
        self.submit, self.now, self.period, self.timeout = submit, now, period, timeout
        self.caller_id = caller_id
        self.remote: Optional[Remote] = None  # cpu and memory of nodes on other hosts (the monitor's agents)
        self.master_uri = rosgraph.get_master_uri()
        self._procs: Dict[int, psutil.Process] = {}
        self._cpu_last: Dict[int, Tuple[float, float]] = {}
        self._run_times: Dict[int, RunTime] = {}
        self._uris: Dict[str, str] = {}
        self._pids: Dict[str, int] = {}  # last pid seen per node, to recognise it without the master
        self._looked_up: Dict[str, float] = {}  # monotonic time the master last gave each node's URI
        self._unregistered: Set[str] = set()  # nodes the master's last answer did not know (and never seen)
        self._local = _local_addresses()
        self._hosts: Dict[str, bool] = {}
        self.port_owners = PortOwners()  # does the pid a node gives own its XML-RPC port (pidcheck.py)
        self._stop = threading.Event()
        self._thread: Optional[threading.Thread] = None
        self._pool = concurrent.futures.ThreadPoolExecutor(max_workers=max(1, min(8, len(nodes))),
                                                           thread_name_prefix="rubass-node")
        self._masters: Dict[int, rpc.Caller] = {}  # a kept connection to the master per sampling thread
        self._masters_lock = threading.Lock()

    def carry(self, old: "NodeSampler") -> None:
        """What the sampler this one replaces (a reload changed the node set) knew of the nodes both
        watch: where each is, its pid, and which the master did not know. A reload while the master
        is away must read them as before, not unknown (a never-registered lidar's stop was released)."""
        for name in self.status:
            for mine, theirs in ((self._uris, old._uris), (self._pids, old._pids), (self._looked_up, old._looked_up)):
                if name in theirs:
                    mine[name] = theirs[name]  # type: ignore[index]
            if name in old._unregistered:
                self._unregistered.add(name)

    def start(self) -> None:
        if self.status:
            self._thread = threading.Thread(target=self._run, name="rubass-nodes", daemon=True)
            self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(2.0)
        self._pool.shutdown(wait=False)
        if self._thread is None or not self._thread.is_alive():
            self._release()  # else the thread does, after its last round: a call cut short would read as a death

    def _release(self) -> None:
        """Close the kept connections and /proc files (no sample is running)."""
        with self._masters_lock:
            callers, self._masters = list(self._masters.values()), {}
        for caller in callers:
            caller.close()
        for pid in list(self._run_times):
            self._forget_process(pid)

    def _master(self) -> rpc.Caller:
        """This thread's kept connection to the master: one per sampling thread, so that a slow
        master delays each sample by its own timeout, not by the others' too."""
        ident = threading.get_ident()
        with self._masters_lock:
            caller = self._masters.get(ident)
            if caller is None or caller.uri != self.master_uri:
                caller = self._masters[ident] = rpc.Caller(self.master_uri, max(self.timeout, 0.5))
            return caller

    def _run(self) -> None:
        next_at = time.monotonic()
        try:
            while not self._stop.is_set():
                list(self._pool.map(self.sample, list(self.status.values())))
                next_at += self.period
                delay = next_at - time.monotonic()
                if delay < 0:
                    next_at = time.monotonic()
                self._stop.wait(max(0.0, delay))
        except RuntimeError:  # the pool was shut down between two rounds
            pass
        finally:
            self._release()

    def sample(self, st: NodeStatus) -> None:
        alive, pid, why = self._ask(st)
        cpu: Any = UNKNOWN
        memory: Any = UNKNOWN
        if alive is True and pid is not None:
            uri = self._uris.get(st.resolved, "")
            if self._is_local(urlparse(uri).hostname or ""):
                wrong = self.port_owners.why_not(st.resolved, uri, pid)  # a node in a container: another pid
                if wrong is not None:
                    why = wrong
                else:
                    note = why[len("alive"):]
                    cpu, memory, why = self._measure(pid)
                    why += note
            elif self.remote is not None:
                cpu, memory, why = self.remote(st.resolved, urlparse(uri).hostname or "", pid)
            else:
                why = f"on host {urlparse(uri).hostname}, not this one: cpu and memory are unknown"
        if st.pid is not None and st.pid != pid:
            self._forget_process(st.pid)  # the node restarted, or died: its old process is gone
        st.alive, st.cpu, st.memory, st.pid, st.why = alive, cpu, memory, pid, why
        self.submit(st.spec_name, self.now(), alive, cpu, memory)

    def _pid_at(self, uri: str) -> Tuple[Optional[int], str]:
        """The pid of the process answering at a node's URI, or None and why not (a hung node
        is found by the timeout: its kernel still accepts the connection)."""
        try:
            # a connection of its own each time: a node that shut down closes its listening socket
            # (refused), though its threads may still serve a connection it had accepted
            code, msg, pid = rpc.Caller(uri, self.timeout, keep_alive=False).call("getPid", self.caller_id)
        except socket.timeout:
            return None, f"did not answer getPid within {self.timeout * 1000:.0f} ms (hung?)"
        except (OSError, xmlrpc.client.Error, ValueError) as exc:
            return None, f"does not answer at {uri}: {exc}"
        if code != 1:
            return None, f"getPid failed: {msg}"
        return int(pid), ""

    def _ask(self, st: NodeStatus) -> Tuple[Any, Optional[int], str]:
        """Alive, the pid and why. Within LOOKUP_PERIOD of the master last naming the node's URI,
        the node alone is asked; if it does not answer there, or another process does, the
        master is asked at once where the node is now."""
        name = st.resolved
        uri = self._uris.get(name)
        if uri is not None and time.monotonic() - self._looked_up.get(name, -math.inf) < self.LOOKUP_PERIOD:
            pid, why = self._pid_at(uri)
            if pid is not None and pid == self._pids.get(name):
                return True, pid, "alive"
            return self._ask_master(st, (uri, pid, why))
        return self._ask_master(st)

    def _ask_master(self, st: NodeStatus, tried: Optional[Tuple[str, Optional[int], str]] = None
                    ) -> Tuple[Any, Optional[int], str]:
        """`tried`: the node's answer at a URI in this sample already (not asked twice: a hung
        node reads dead after one timeout, not two)."""
        name = st.resolved
        note = ""
        try:  # the master with a timeout too: a hung master must not stall every sample
            code, msg, uri = self._master().call("lookupNode", self.caller_id, name)
        except (OSError, socket.error, xmlrpc.client.Error, ValueError) as exc:
            code, msg, uri = -2, str(exc), None
        if code == 1:
            self._uris[name] = uri
            self._looked_up[name] = time.monotonic()
            self._unregistered.discard(name)
        else:
            uri = self._uris.get(name)
            if uri is None:
                if code != -2:
                    self._unregistered.add(name)
                    return False, None, "not registered with the master"
                if name in self._unregistered:  # still so: no node can register while the master is away
                    return False, None, (f"not registered with the master at its last answer; the master cannot "
                                         f"be reached now ({msg}), and no node registers without it")
                return UNKNOWN, None, f"the master cannot be reached ({msg}) and the node was never seen"
            # the master is down, or restarted and does not know the node (rospy nodes do not
            # re-register): ask the node where it was; alive only if it is the same process
            note = " (the master cannot be reached)" if code == -2 else " (not registered with the master: restarted?)"
        pid, why = tried[1:] if tried is not None and tried[0] == uri else self._pid_at(uri)
        if pid is None:
            return False, None, why
        known = self._pids.get(name)
        if note and known is not None and int(pid) != known:
            return False, None, f"another process (pid {pid}) answers at {uri}{note}"
        self._pids[name] = int(pid)
        return True, int(pid), "alive" + note

    def _is_local(self, host: str) -> bool:
        if host not in self._hosts:
            try:
                self._hosts[host] = host in self._local or socket.gethostbyname(host) in self._local
            except OSError:
                self._hosts[host] = False
        return self._hosts[host]

    def _measure(self, pid: int) -> Tuple[Any, Any, str]:
        proc = self._procs.get(pid)
        try:
            if proc is None:
                proc = self._procs[pid] = psutil.Process(pid)
            memory = float(proc.memory_info().rss)
            cpu = self._cpu(pid, proc)
        except (psutil.NoSuchProcess, psutil.AccessDenied, psutil.ZombieProcess) as exc:
            self._forget_process(pid)
            return UNKNOWN, UNKNOWN, f"cannot measure process {pid}: {exc.__class__.__name__}"
        return cpu, memory, "alive" if cpu is not UNKNOWN else "alive (cpu known from the next sample)"

    def _cpu(self, pid: int, proc: psutil.Process) -> Any:
        """CPU share of one core since the last sample. From the threads' run times in
        nanoseconds (/proc/PID/task/*/schedstat) where Linux gives them: psutil's clock-tick
        CPU times (10 ms) would quantize a 0.1 s sample to steps of 10 %."""
        reader = self._run_times.get(pid)
        if reader is None:
            reader = self._run_times[pid] = RunTime(pid)
        used = reader.seconds()
        if used is None:
            times = proc.cpu_times()
            used = times.user + times.system
        now = time.monotonic()
        last = self._cpu_last.get(pid)
        self._cpu_last[pid] = (now, used)
        if last is None or now - last[0] <= 0:
            return UNKNOWN  # the first reading only starts the count
        return max(0.0, used - last[1]) / (now - last[0])

    def _forget_process(self, pid: int) -> None:
        self._procs.pop(pid, None)
        self._cpu_last.pop(pid, None)
        reader = self._run_times.pop(pid, None)
        if reader is not None:
            reader.close()
