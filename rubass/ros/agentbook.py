"""Agent reports: the JSON a `rubass agent` publishes, and the monitor's book of them.

Pure (no rospy, no psutil, no clock): the monitor and `rubass replay` both use it, with the
time as an argument. One report per agent and period on AGENT_TOPIC (std_msgs/String):

    {"agent": "/rubass_agent_hostb", "host": "hostb", "addresses": ["10.0.0.2", "hostb"],
     "time": 1700000000.1, "period": 0.1, "seq": 42,
     "nodes": [{"node": "/controller", "time": 1700000000.1, "alive": true, "cpu": 0.97,
                "memory": 51234816.0, "pid": 4242, "uri": "http://10.0.0.2:40123/", "why": "alive"}]}

Each entry of `nodes` is a sample in the monitor's own `~node_samples` format (node, time,
alive, cpu, memory; null where unknown) plus pid, uri and why. A report is also the agent's
heartbeat: it is sent every period even when the host runs no node. A report older than
STALE_PERIODS of its agent's period is stale: the nodes it covers are unknown. An agent that
exits cleanly sends a last report with `"leaving": true`: it is dropped at once.

For a node, the book uses the freshest report *that contains the node* among the fresh agents
of its host (AgentBook.choose): the monitor (`lookup`) and `rubass replay` (`sample`) apply this
one rule.
"""
from __future__ import annotations

import json
import logging
import math
import threading
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Optional, Set, Tuple, Union
from urllib.parse import urlparse

from ..engine.values import UNKNOWN
from ..lang.errors import counted

AGENT_TOPIC = "/rubass/agent_samples"
STALE_PERIODS = 3.0
COVERED_DROP_AFTER = 30.0  # s: a silent agent whose host another fresh agent reports is listed this long, then dropped
WARN_EVERY = 10.0  # s: at most one warning this often about invalid entries (whichever agent sends them)
_LOOPBACK = ("127.", "::1", "localhost")


@dataclass(frozen=True)
class NodeReport:
    node: str          # resolved name, e.g. /controller
    alive: Any         # True, False or None (unknown)
    cpu: Optional[float]
    memory: Optional[float]
    pid: Optional[int]
    why: str
    host: str = ""     # the host of the node's URI, as the agent found it ("" if not given)


@dataclass(frozen=True)
class AgentReport:
    agent: str
    host: str
    addresses: Tuple[str, ...]
    time: float
    period: float
    nodes: Dict[str, NodeReport] = field(default_factory=dict)
    leaving: bool = False            # the agent's last report: it exits
    invalid: Tuple[str, ...] = ()    # entries left out, and why


def _known(v: Any) -> Optional[float]:
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) and v == v else None


def _measure(v: Any) -> Tuple[Optional[float], bool]:
    """(value, valid) of a reported cpu or memory: null is unknown; only a finite number >= 0 is a value."""
    if v is None:
        return None, True
    if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v >= 0:
        return float(v), True
    return None, False


def is_loopback(address: str) -> bool:
    return address.startswith(_LOOPBACK)


def stale_at(at: float, period: float) -> float:
    """When a report received at `at` from an agent of this period turns stale (from that instant on)."""
    return at + STALE_PERIODS * period


def node_entry(node: str, time: float, alive: Any, cpu: Any, memory: Any, pid: Optional[int], uri: str,
               why: str) -> Dict[str, Any]:
    """One node's entry of a report (unknown values become null)."""
    return {"node": node, "time": time, "alive": alive if isinstance(alive, bool) else None,
            "cpu": _measure(_known(cpu))[0], "memory": _measure(_known(memory))[0], "pid": pid, "uri": uri,
            "why": why}


def encode(agent: str, host: str, addresses: List[str], time: float, period: float, seq: int,
           nodes: List[Dict[str, Any]], leaving: bool = False) -> str:
    """A report as the JSON text an agent publishes (`leaving`: its last one, as it exits)."""
    d = {"agent": agent, "host": host, "addresses": sorted(a for a in addresses if not is_loopback(a)),
         "time": time, "period": period, "seq": seq, "nodes": nodes}
    if leaving:
        d["leaving"] = True
    return json.dumps(d, sort_keys=True)


def _host_of(uri: Any) -> str:
    try:
        return urlparse(uri).hostname or "" if isinstance(uri, str) else ""
    except ValueError:
        return ""


def _entry(agent: str, n: Dict[str, Any]) -> Union[NodeReport, str]:
    """A node's entry, or why it is invalid."""
    cpu, cpu_ok = _measure(n.get("cpu"))
    memory, memory_ok = _measure(n.get("memory"))
    if not (cpu_ok and memory_ok):
        return (f"agent {agent}: node {n['node']}: cpu {n.get('cpu')!r}, memory {n.get('memory')!r}: each must be "
                f"a number >= 0 or null")
    alive = n.get("alive") if isinstance(n.get("alive"), bool) else None
    pid = n.get("pid") if isinstance(n.get("pid"), int) and not isinstance(n.get("pid"), bool) else None
    return NodeReport(n["node"], alive, cpu, memory, pid, str(n.get("why", "")), _host_of(n.get("uri")))


def decode(text: str) -> AgentReport:
    """A report from its JSON text; ValueError saying what is wrong with it. An entry with an
    impossible cpu or memory (negative, NaN, not a number) is left out and named in `invalid`."""
    try:
        d = json.loads(text)
    except ValueError as exc:
        raise ValueError(f"not JSON ({exc})") from None
    if not isinstance(d, dict):
        raise ValueError("not a JSON object")
    agent, period, nodes = d.get("agent"), d.get("period"), d.get("nodes")
    if not isinstance(agent, str) or not agent:
        raise ValueError("'agent' must be the agent's node name")
    if _known(period) is None or not 0.0 < float(period) <= 3600.0:
        raise ValueError(f"agent {agent}: 'period' must be a number of seconds (0 < period <= 3600), got {period!r}")
    if not isinstance(nodes, list):
        raise ValueError(f"agent {agent}: 'nodes' must be a list")
    out: Dict[str, NodeReport] = {}
    invalid: List[str] = []
    for n in nodes:
        if not isinstance(n, dict) or not isinstance(n.get("node"), str):
            raise ValueError(f"agent {agent}: every entry of 'nodes' needs a 'node' name")
        entry = _entry(agent, n)
        if isinstance(entry, str):
            invalid.append(entry)
        else:
            out[n["node"]] = entry
    addresses = d.get("addresses") if isinstance(d.get("addresses"), list) else []
    host = d.get("host") if isinstance(d.get("host"), str) else ""
    return AgentReport(agent, host, tuple(str(a) for a in addresses if not is_loopback(str(a)))
                       + ((host,) if host and not is_loopback(host) else ()),
                       _known(d.get("time")) or 0.0, float(period), out, d.get("leaving") is True, tuple(invalid))


@dataclass
class _Heard:
    report: AgentReport
    at: float        # when the monitor received it, on the monitor's clock
    reports: int = 1

    @property
    def stale_at(self) -> float:
        return stale_at(self.at, self.report.period)


@dataclass(frozen=True)
class _Left:
    agent: str
    addresses: Tuple[str, ...]
    nodes: Tuple[str, ...]   # what its last reports covered
    at: float


# rospy sends the records of its 'rosout' logger to stderr and /rosout; without rospy a plain logger
_ROSOUT = logging.getLogger("rosout")


class AgentBook:
    """The latest report of every agent, with when it came; thread-safe (updated by the
    subscriber's thread, read by the node sampler's). `warn` gets the throttled warnings about
    invalid entries."""

    def __init__(self, warn: Optional[Callable[[str], None]] = None) -> None:
        self._agents: Dict[str, _Heard] = {}
        self._left: Dict[str, _Left] = {}
        self._warned = -math.inf  # when invalid entries were last warned about
        self._warned_caller = -math.inf  # when a report in another agent's name was last warned about
        self._lock = threading.Lock()
        self.warn: Callable[[str], None] = warn if warn is not None else _ROSOUT.warning

    def update(self, report: AgentReport, at: float, caller: Optional[str] = None) -> bool:
        """A report heard at `at`, from the node `caller` (its publisher, from the connection header; None
        where it is not known); whether it was taken. A report whose publisher is not the agent it names
        is ignored: a stray or forged report (a leaving one included) must not stand in for a real agent."""
        if caller is not None and caller != report.agent:
            if at - self._warned_caller >= WARN_EVERY:
                self._warned_caller = at
                self.warn(f"rubass: ignoring a report on {AGENT_TOPIC} published by {caller} in the name of agent "
                          f"{report.agent}: only an agent's own reports count")
            return False
        if report.invalid and at - self._warned >= WARN_EVERY:
            self._warned = at
            n = len(report.invalid)
            self.warn(f"rubass: ignoring {n} entr{'y' if n == 1 else 'ies'} of a report on {AGENT_TOPIC} "
                      f"(no value: as if not reported): " + "; ".join(report.invalid))
        with self._lock:
            old = self._agents.pop(report.agent, None)
            self._left.pop(report.agent, None)
            if report.leaving:  # dropped at once: its nodes fall to another agent of the host, or unknown
                nodes = set(report.nodes) | (set(old.report.nodes) if old else set())
                for g in list(self._left.values()):  # one per host: the latest to leave
                    if set(g.addresses) & set(report.addresses):
                        del self._left[g.agent]
                self._left[report.agent] = _Left(report.agent, report.addresses, tuple(sorted(nodes)), at)
                return True
            self._agents[report.agent] = _Heard(report, at, old.reports + 1 if old else 1)
        return True

    def _candidates(self, node: str, host: str) -> List[_Heard]:
        """The agents of `host` (by address), else those that reported `node`."""
        with self._lock:
            heard = list(self._agents.values())
        by_host = [h for h in heard if host and host in h.report.addresses]
        return by_host or [h for h in heard if node in h.report.nodes]

    def choose(self, node: str, host: str, pid: Optional[int], at: float) -> Tuple[Optional[_Heard], Any]:
        """(agent, its NodeReport) to use for `node` on `host` answering with `pid` (None: any):
        the freshest report containing the node among the fresh agents of its host, one with the
        same pid preferred; else (agent or None, why not)."""
        candidates = self._candidates(node, host)
        fresh = [h for h in candidates if at < h.stale_at]
        having = [h for h in fresh if node in h.report.nodes]
        if having:  # one that measured the pid answering now first, then one that gave no pid, then any
            same = [h for h in having if pid is not None and h.report.nodes[node].pid == pid]
            unsure = [h for h in having if h.report.nodes[node].pid is None]
            best = max(same or unsure or having, key=lambda h: h.at)
            return best, best.report.nodes[node]
        if fresh:
            best = max(fresh, key=lambda h: h.at)
            return best, f"on host {host}: agent {best.report.agent} does not report this node (yet)"
        with self._lock:
            left = [g for g in self._left.values() if (host and host in g.addresses) or node in g.nodes]
        last = max(candidates, key=lambda h: h.at) if candidates else None
        gone = max(left, key=lambda g: g.at) if left else None
        if gone is not None and (last is None or gone.at >= last.at):
            return None, (f"agent {gone.agent} left (it exited) and no other agent reports host {host}: "
                          f"cpu and memory are unknown")
        if last is None:
            return None, (f"on host {host}, where no rubass agent reports (run 'rosrun rubass agent' there): "
                          f"cpu and memory are unknown")
        r = last.report
        return last, (f"agent {r.agent} on host {r.host or host} is silent: its last report came {at - last.at:.1f} s "
                      f"ago (more than {STALE_PERIODS:g} periods of {r.period:g} s): cpu and memory are unknown")

    def lookup(self, node: str, host: str, pid: Optional[int], at: float) -> Tuple[Any, Any, str]:
        """(cpu, memory, why) of `node` (resolved name) on `host`, whose process answered with
        `pid`: from the report `choose` finds; UNKNOWN and why otherwise."""
        h, n = self.choose(node, host, pid, at)
        if h is None or not isinstance(n, NodeReport):
            return UNKNOWN, UNKNOWN, n
        agent = h.report.agent
        if pid is not None and n.pid is not None and n.pid != pid:
            return UNKNOWN, UNKNOWN, (f"agent {agent} measured pid {n.pid}, but pid {pid} answers (restarted?): "
                                      f"cpu and memory unknown until its next report")
        if n.cpu is None and n.memory is None:
            return UNKNOWN, UNKNOWN, f"agent {agent}: {n.why or 'cannot measure this node'}"
        if n.cpu is None:
            return UNKNOWN, n.memory, f"alive (agent {agent}: {n.why or 'cpu unknown'})"
        return n.cpu, n.memory, "alive"

    def sample(self, node: str, host: str, at: float) -> Tuple[Any, Any, Any]:
        """(alive, cpu, memory) of `node` as the agents report it (None where unknown), for replay."""
        h, n = self.choose(node, host, None, at)
        return (n.alive, n.cpu, n.memory) if h is not None and isinstance(n, NodeReport) else (None, None, None)

    def _prune(self, at: float) -> List[_Heard]:
        """Drop agents silent for COVERED_DROP_AFTER whose host another fresh agent reports (an
        agent relaunched under a new name); the agents heard, by name."""
        dropped = []
        with self._lock:
            heard = list(self._agents.values())
            fresh = {h.report.host: h.report.agent for h in heard if at < h.stale_at and h.report.host}
            for h in heard:
                if h.report.host in fresh and at >= h.stale_at + COVERED_DROP_AFTER:
                    del self._agents[h.report.agent]
                    dropped.append(f"rubass: agent {h.report.agent} on {h.report.host} has been silent for "
                                   f"{at - h.at:.1f} s while {fresh[h.report.host]} reports its host: "
                                   f"dropped from the list of agents")
            kept = sorted(self._agents.values(), key=lambda h: h.report.agent)
        for text in dropped:
            self.warn(text)
        return kept

    def conflicts(self, at: float) -> List[str]:
        """'agents /a and /b both report host H' for every host more than one fresh agent claims."""
        by_host: Dict[str, Set[str]] = {}
        with self._lock:
            for h in self._agents.values():
                if at < h.stale_at and h.report.host:
                    by_host.setdefault(h.report.host, set()).add(h.report.agent)
        return [f"agents {', '.join(sorted(a)[:-1])} and {sorted(a)[-1]} {'both' if len(a) == 2 else 'all'} report "
                f"host {host}"
                for host, a in sorted(by_host.items()) if len(a) > 1]

    def silent(self, at: float) -> List[str]:
        """Agents whose last report is stale, as 'AGENT on HOST for N s' (the monitor's status WARNs, as
        it does for `conflicts`)."""
        heard = self._prune(at)
        fresh = {h.report.host: h.report.agent for h in heard if at < h.stale_at and h.report.host}
        out = []
        for h in heard:
            if at >= h.stale_at:
                other = fresh.get(h.report.host)
                also = f" (host reported by {other} now)" if other else ""
                out.append(f"{h.report.agent} on {h.report.host or '?'} for {at - h.at:.1f} s{also}")
        return out

    def summary(self, at: float) -> str:
        """One line for /diagnostics: every agent, its host, its nodes and its last report's age."""
        heard = self._prune(at)
        with self._lock:
            left = sorted(self._left.values(), key=lambda g: g.agent)
        parts = [f"{h.report.agent} on {h.report.host or '?'}: {'SILENT' if at >= h.stale_at else 'ok'}, "
                 f"{counted(len(h.report.nodes), 'node')}, last report {at - h.at:.1f} s ago" for h in heard]
        parts += [f"{g.agent}: left {at - g.at:.1f} s ago" for g in left if at < g.at + COVERED_DROP_AFTER]
        return "; ".join(parts) or "none heard"
