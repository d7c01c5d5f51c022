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
STALE_PERIODS of its agent's period is stale: the nodes it covers are unknown.
"""
from __future__ import annotations

import json
import threading
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Tuple

from ..engine.values import UNKNOWN

AGENT_TOPIC = "/rubass/agent_samples"
STALE_PERIODS = 3.0
_LOOPBACK = ("127.", "::1", "localhost")


@dataclass(frozen=True)
class NodeReport:
    node: str          # resolved name, e.g. /controller
    alive: Any         # True, False or None (unknown)
    cpu: Optional[float]
    memory: Optional[float]
    pid: Optional[int]
    why: str


@dataclass(frozen=True)
class AgentReport:
    agent: str
    host: str
    addresses: Tuple[str, ...]
    time: float
    period: float
    nodes: Dict[str, NodeReport] = field(default_factory=dict)


def _known(v: Any) -> Optional[float]:
    return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) and v == v else None


def is_loopback(address: str) -> bool:
    return address.startswith(_LOOPBACK)


def node_entry(node: str, time: float, alive: Any, cpu: Any, memory: Any, pid: Optional[int], uri: str,
               why: str) -> Dict[str, Any]:
    """One node's entry of a report (unknown values become null)."""
    return {"node": node, "time": time, "alive": alive if isinstance(alive, bool) else None, "cpu": _known(cpu),
            "memory": _known(memory), "pid": pid, "uri": uri, "why": why}


def encode(agent: str, host: str, addresses: List[str], time: float, period: float, seq: int,
           nodes: List[Dict[str, Any]]) -> str:
    """A report as the JSON text an agent publishes."""
    return json.dumps({"agent": agent, "host": host, "addresses": sorted(a for a in addresses if not is_loopback(a)),
                       "time": time, "period": period, "seq": seq, "nodes": nodes}, sort_keys=True)


def decode(text: str) -> AgentReport:
    """A report from its JSON text; ValueError saying what is wrong with it."""
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
    for n in nodes:
        if not isinstance(n, dict) or not isinstance(n.get("node"), str):
            raise ValueError(f"agent {agent}: every entry of 'nodes' needs a 'node' name")
        alive = n.get("alive") if isinstance(n.get("alive"), bool) else None
        pid = n.get("pid") if isinstance(n.get("pid"), int) and not isinstance(n.get("pid"), bool) else None
        out[n["node"]] = NodeReport(n["node"], alive, _known(n.get("cpu")), _known(n.get("memory")), pid,
                                    str(n.get("why", "")))
    addresses = d.get("addresses") if isinstance(d.get("addresses"), list) else []
    host = d.get("host") if isinstance(d.get("host"), str) else ""
    return AgentReport(agent, host, tuple(str(a) for a in addresses if not is_loopback(str(a)))
                       + ((host,) if host and not is_loopback(host) else ()),
                       _known(d.get("time")) or 0.0, float(period), out)


@dataclass
class _Heard:
    report: AgentReport
    at: float        # when the monitor received it, on the monitor's clock
    reports: int = 1


class AgentBook:
    """The latest report of every agent, with when it came; thread-safe (updated by the
    subscriber's thread, read by the node sampler's)."""

    def __init__(self) -> None:
        self._agents: Dict[str, _Heard] = {}
        self._lock = threading.Lock()

    def update(self, report: AgentReport, at: float) -> None:
        with self._lock:
            old = self._agents.get(report.agent)
            self._agents[report.agent] = _Heard(report, at, old.reports + 1 if old else 1)

    def _stale_after(self, heard: _Heard) -> float:
        return STALE_PERIODS * heard.report.period

    def _responsible(self, node: str, host: str) -> Optional[_Heard]:
        """The agent of `host` (by address), else the last that reported `node`; the freshest if several."""
        with self._lock:
            heard = list(self._agents.values())
        by_host = [h for h in heard if host and host in h.report.addresses]
        by_node = [h for h in heard if node in h.report.nodes]
        candidates = by_host or by_node
        return max(candidates, key=lambda h: h.at) if candidates else None

    def lookup(self, node: str, host: str, pid: Optional[int], at: float) -> Tuple[Any, Any, str]:
        """(cpu, memory, why) of `node` (resolved name) on `host`, whose process answered with
        `pid`: from its agent's latest report if that is fresh; UNKNOWN and why otherwise."""
        h = self._responsible(node, host)
        if h is None:
            return UNKNOWN, UNKNOWN, (f"on host {host}, where no rubass agent reports (run 'rosrun rubass agent' "
                                      f"there): cpu and memory are unknown")
        r, age = h.report, at - h.at
        if age > self._stale_after(h):
            return UNKNOWN, UNKNOWN, (f"agent {r.agent} on host {r.host or host} is silent: its last report came "
                                f"{age:.1f} s ago (more than {STALE_PERIODS:g} periods of {r.period:g} s): "
                                f"cpu and memory are unknown")
        n = r.nodes.get(node)
        if n is None:
            return UNKNOWN, UNKNOWN, f"on host {host}: agent {r.agent} does not report this node (yet)"
        if pid is not None and n.pid is not None and n.pid != pid:
            return UNKNOWN, UNKNOWN, (f"agent {r.agent} measured pid {n.pid}, but pid {pid} answers (restarted?): "
                                f"cpu and memory unknown until its next report")
        if n.cpu is None and n.memory is None:
            return UNKNOWN, UNKNOWN, f"agent {r.agent}: {n.why or 'cannot measure this node'}"
        if n.cpu is None:
            return UNKNOWN, n.memory, f"alive (agent {r.agent}: {n.why or 'cpu unknown'})"
        return n.cpu, n.memory, "alive"

    def silent(self, at: float) -> List[str]:
        """Agents whose last report is stale, as 'AGENT on HOST for N s'."""
        with self._lock:
            heard = sorted(self._agents.values(), key=lambda h: h.report.agent)
        return [f"{h.report.agent} on {h.report.host or '?'} for {at - h.at:.1f} s" for h in heard
                if at - h.at > self._stale_after(h)]

    def summary(self, at: float) -> str:
        """One line for /diagnostics: every agent, its host, its nodes and its last report's age."""
        with self._lock:
            heard = sorted(self._agents.values(), key=lambda h: h.report.agent)
        if not heard:
            return "none heard"
        parts = []
        for h in heard:
            state = "SILENT" if at - h.at > self._stale_after(h) else "ok"
            parts.append(f"{h.report.agent} on {h.report.host or '?'}: {state}, {len(h.report.nodes)} nodes, "
                         f"last report {at - h.at:.1f} s ago")
        return "; ".join(parts)
