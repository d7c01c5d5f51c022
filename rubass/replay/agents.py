"""Recorded agent reports (`/rubass/agent_samples`) turned into node samples for replay.

Pure: it wraps the stream of recorded messages. Each report becomes one node sample per spec
node it covers, in the format of the monitor's `~node_samples`, on the topic SAMPLES; when an
agent's reports stop for more than three of its periods (as the live monitor judges), the
nodes it covered become unknown at that instant. Nodes that the monitor's own recorded
samples cover are left to those: they are what the live engine saw.
"""
from __future__ import annotations

import heapq
import json
from typing import Any, Dict, Iterable, Iterator, List, Optional, Set, Tuple

from ..ros.agentbook import STALE_PERIODS, decode

SAMPLES = "<agent samples>"
Record = Tuple[float, str, Optional[Any]]


class _Sample:
    """A stand-in for a std_msgs/String carrying a node sample's JSON."""

    __slots__ = ("data",)

    def __init__(self, data: str) -> None:
        self.data = data


def _sample(node: str, alive: Any, cpu: Any, memory: Any) -> _Sample:
    return _Sample(json.dumps({"node": node, "alive": alive, "cpu": cpu, "memory": memory}))


def agent_samples(stream: Iterable[Record], agent_topics: Set[str], names: Dict[str, str], skip: Set[str],
                  end: float) -> Iterator[Record]:
    """`stream` with each agent report replaced by node samples on SAMPLES.

    names: resolved node name -> the spec's name; skip: spec names left to the monitor's own
    samples; end: the recording's end (bag time), past which no expiry is emitted.
    """
    covers: Dict[str, Tuple[float, List[str]]] = {}  # agent -> (stale at, spec nodes of its last report)
    expiries: List[Tuple[float, str]] = []

    def expire(until: float) -> Iterator[Record]:
        while expiries and expiries[0][0] < until:
            at, agent = heapq.heappop(expiries)
            due = covers.get(agent)
            if due is not None and due[0] == at:  # not superseded by a newer report
                del covers[agent]
                for node in due[1]:
                    yield at, SAMPLES, _sample(node, None, None, None)

    for stamp, topic, msg in stream:
        yield from expire(stamp)
        if topic not in agent_topics:
            yield stamp, topic, msg
            continue
        try:
            report = decode(msg.data)
        except (ValueError, AttributeError):
            continue
        nodes = []
        for resolved, n in sorted(report.nodes.items()):
            spec_name = names.get(resolved)
            if spec_name is None or spec_name in skip:
                continue
            nodes.append(spec_name)
            yield stamp, SAMPLES, _sample(spec_name, n.alive, n.cpu, n.memory)
        stale_at = stamp + STALE_PERIODS * report.period
        covers[report.agent] = (stale_at, nodes)
        heapq.heappush(expiries, (stale_at, report.agent))
    yield from expire(end)
