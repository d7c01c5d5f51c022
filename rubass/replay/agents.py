"""Recorded agent reports (`/rubass/agent_samples`) turned into node samples for replay.

Pure: it wraps the stream of recorded messages. The reports go into an AgentBook on the
recording's clock, the book the live monitor keeps, so a node's values follow the live rule
exactly: the freshest report containing the node among its host's fresh agents; unknown
when none is fresh (more than three periods silent), when its agent left, or when it reports
nothing for the node. After each report, and at each instant a report turns stale, every spec
node the book knows gets a node sample (format of the monitor's `~node_samples`) on the topic
SAMPLES if it is in that report or its value changed. Nodes that the monitor's own recorded
samples cover are left to those: they are what the live engine saw.
"""
from __future__ import annotations

import heapq
import json
from typing import Any, Callable, Dict, Iterable, Iterator, List, Optional, Set, Tuple

from ..ros.agentbook import AgentBook, decode, stale_at

SAMPLES = "<agent samples>"
Record = Tuple[float, str, Optional[Any]]


class _Sample:
    """A stand-in for a std_msgs/String carrying a node sample's JSON."""

    __slots__ = ("data",)

    def __init__(self, data: str) -> None:
        self.data = data


def _sample(node: str, alive: Any, cpu: Any, memory: Any) -> _Sample:
    return _Sample(json.dumps({"node": node, "alive": alive, "cpu": cpu, "memory": memory}))


class _Replayed:
    """The book on the recording's clock, and the last sample given for each spec node."""

    def __init__(self, names: Dict[str, str], skip: Set[str], warn: Callable[[str], None]) -> None:
        self.book = AgentBook(warn=warn)
        self.agents: Set[str] = set()  # publishers seen reporting in their own name: agents
        self.names, self.skip = names, skip
        self.hosts: Dict[str, str] = {}  # resolved node -> its host, from the latest entry naming it
        self.given: Dict[str, Tuple[Any, Any, Any]] = {}
        self.wakeups: List[float] = []

    def add(self, stamp: float, text: str, caller: Optional[str] = None) -> Set[str]:
        """A report into the book, from its publisher `caller` (None: not recorded); the resolved nodes it
        contains (ValueError if it is not one)."""
        report = decode(text)
        if caller == report.agent:
            self.agents.add(caller)
        elif caller in self.agents:
            # `rosbag filter`/`compress` write one connection per topic, under its first publisher's name:
            # an agent never reports in another's name, so that name says nothing of who published
            caller = None
        if not self.book.update(report, stamp, caller):
            return set()  # in another agent's name: ignored, as live
        for node, n in report.nodes.items():
            # only the spec's nodes, and those the monitor's samples do not cover (skip: resolved names)
            if self.names.get(node) is not None and node not in self.skip and self.names[node] not in self.skip:
                self.hosts[node] = n.host or report.host
        if not report.leaving:
            heapq.heappush(self.wakeups, stale_at(stamp, report.period))
        return set() if report.leaving else set(report.nodes)

    def samples(self, at: float, reported: Set[str]) -> Iterator[Record]:
        for node, host in sorted(self.hosts.items()):
            spec_name = self.names[node]
            value = self.book.sample(node, host, at)
            if spec_name not in self.given and value == (None, None, None):
                continue  # nothing known of it yet: no sample
            if node in reported or self.given.get(spec_name) != value:
                self.given[spec_name] = value
                yield at, SAMPLES, _sample(spec_name, *value)


def agent_samples(stream: Iterable[Record], agent_topics: Set[str], names: Dict[str, str], skip: Set[str],
                  end: float, warn: Callable[[str], None] = lambda text: None,
                  keep: Set[str] = frozenset()) -> Iterator[Record]:  # type: ignore[assignment]
    """`stream` with each agent report replaced by node samples on SAMPLES.

    names: resolved node name -> the spec's name; skip: nodes left to the monitor's own samples,
    resolved (as `command._sampled_nodes` gives them; a spec name there counts too); end: the
    recording's end (bag time), past which no expiry is emitted; warn: what the monitor would log
    (a report ignored); keep: agent topics the spec reads, passed on as well.
    """
    state = _Replayed(names, skip, warn)
    done = -1.0

    def expire(until: float) -> Iterator[Record]:
        nonlocal done
        while state.wakeups and state.wakeups[0] < until:
            at = heapq.heappop(state.wakeups)
            if at != done:  # several agents' reports may turn stale at one instant
                done = at
                yield from state.samples(at, set())

    for stamp, topic, msg in stream:
        yield from expire(stamp)
        if topic not in agent_topics:
            yield stamp, topic, msg
            continue
        if topic in keep:  # the spec reads the agents' topic itself (age(), frequency())
            yield stamp, topic, msg
        try:
            reported = state.add(stamp, msg.data, getattr(msg, "_connection_header", {}).get("callerid"))
        except (ValueError, AttributeError):
            continue
        yield from state.samples(stamp, reported)
    yield from expire(end)
