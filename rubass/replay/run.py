"""Driving the engine over recorded messages: each at its time, ticks in between, and
messages of different topics that share a timestamp evaluated together. Pure: the recording is
any iterable."""
from __future__ import annotations

import json
from typing import Any, Dict, Iterable, List, Optional, Set, Tuple

from ..engine import UNKNOWN, Engine, Event
from ..lang.model import CheckedSpec
from ..lang.topicnames import monitor_node, resolve


def replay(spec: CheckedSpec, messages: Iterable[Tuple[float, str, Optional[Any]]], start: float, end: float,
           rate: float = 50.0, node_topics: Iterable[str] = ()) -> Tuple[Engine, List[Event]]:
    """Events with times in seconds since `start`; every spec topic is watched from `start`.

    Messages on `node_topics` are the monitor's recorded node samples (JSON with node, alive,
    cpu, memory), fed to the engine as samples, to every spelling of their node in the spec
    (NodeNames). Messages of different topics at one timestamp are evaluated together; a second
    message of a topic already in that batch is evaluated after it, at the same instant.
    """
    node_topics = set(node_topics)
    node_names = NodeNames(spec.nodes)
    engine = Engine(spec, 0.0, origin=start)  # times run from 0; header stamps stay absolute
    events = engine.evaluate_all(0.0)
    extend, on_messages = events.extend, engine.on_messages
    period = 1.0 / rate
    next_tick = period
    batch: List[Tuple[str, Optional[Any]]] = []
    in_batch: Set[str] = set()  # the topics of `batch`
    batch_time = 0.0

    def ticks_until(t: float, inclusive: bool) -> None:
        nonlocal next_tick
        while next_tick < t or (inclusive and next_tick == t):
            extend(engine.on_tick(next_tick))
            next_tick = round((next_tick + period) / period) * period  # no drift over long bags

    for stamp, topic, msg in messages:  # per message: kept short, it runs a million times a replay
        t = stamp - start
        if topic in node_topics:
            if batch:
                extend(on_messages(batch_time, batch))
                batch, in_batch = [], set()
            ticks_until(t, inclusive=False)
            sample = _node_sample(msg)
            if sample is not None:
                # at the instant the monitor took it (recorded in the sample), as the live engine did
                at = max(min(t, sample[4] - start), engine.store.now) if sample[4] is not None else t
                for node in node_names.of(sample[0], topic):
                    extend(engine.on_node_sample(node, at, *sample[1:4]))
            batch_time = t  # the ticks before t are done
            continue
        if t != batch_time:
            if batch:
                extend(on_messages(batch_time, batch))
                batch, in_batch = [], set()
            if next_tick < t:
                ticks_until(t, inclusive=False)
            batch_time = t
        elif topic in in_batch:  # a second message of a topic at one instant: each is evaluated, as live
            extend(on_messages(batch_time, batch))
            batch, in_batch = [], set()
        batch.append((topic, msg))
        in_batch.add(topic)
    if batch:
        extend(on_messages(batch_time, batch))
    ticks_until(end - start, inclusive=True)
    extend(engine.advance(end - start))
    return engine, events


def monitor_of(topic: str) -> str:
    """The node that published a recorded `~node_samples` topic (`/ns/rubass/node_samples` -> `/ns/rubass`);
    the default monitor for a topic of another shape (the agents' samples, a rule test's)."""
    head, _, tail = topic.rpartition("/")
    return head if tail == "node_samples" and head.startswith("/") else monitor_node()


def resolve_node(name: str, monitor: Optional[str] = None) -> str:
    """A node name as the monitor `monitor` (monitor_node() by default) resolves it (rospy.resolve_name):
    relative names in its namespace, private `~x` under it."""
    return resolve(name, monitor)


class NodeNames:
    """Which spec spellings of a node a recorded node sample is for.

    The live monitor samples each spelling of a node (`controller`, `/controller`) under its resolved
    name and records the spelling it sampled; the spec replayed may spell the node otherwise. A sample
    goes to every spelling in the spec that names the same node: the recorded name resolved in the
    namespace of the monitor that recorded it (from its topic), the spec's as replay resolves topics
    (docs/replay.md). A spelling the recording has samples of itself gets only those, from its first.
    """

    def __init__(self, nodes: Iterable[str]) -> None:
        self.nodes = set(nodes)
        self.by_node: Dict[str, List[str]] = {}
        for n in sorted(self.nodes):
            self.by_node.setdefault(resolve_node(n), []).append(n)
        self.exact: Set[str] = set()  # spellings of the spec seen recorded as they are

    def of(self, name: str, topic: str) -> List[str]:
        """The spec's spellings that a sample of `name` recorded on `topic` is for (samples are few a second)."""
        if name in self.nodes:
            self.exact.add(name)
        spelled = self.by_node.get(resolve_node(name, monitor_of(topic)), [])
        return [n for n in spelled if n == name or n not in self.exact]


def _node_sample(msg: Any) -> Optional[Tuple[str, Any, Any, Any, Optional[float]]]:
    """(node, alive, cpu, memory, sample time) from a recorded ~node_samples message; None if unreadable."""
    try:
        d = json.loads(msg.data)
        at = d.get("time")
        return (str(d["node"]), _known(d.get("alive")), _known(d.get("cpu")), _known(d.get("memory")),
                float(at) if isinstance(at, (int, float)) else None)
    except (ValueError, KeyError, TypeError, AttributeError):
        return None


def _known(v: Any) -> Any:
    if v is True or v is False:
        return v
    return float(v) if isinstance(v, (int, float)) else UNKNOWN
