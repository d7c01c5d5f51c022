"""Driving the engine over recorded messages: each at its time, ticks in between, and
messages that share a timestamp evaluated together. Pure: the recording is any iterable."""
from __future__ import annotations

import json
from typing import Any, Iterable, List, Optional, Tuple

from ..engine import UNKNOWN, Engine, Event
from ..lang.model import CheckedSpec


def replay(spec: CheckedSpec, messages: Iterable[Tuple[float, str, Optional[Any]]], start: float, end: float,
           rate: float = 50.0, node_topics: Iterable[str] = ()) -> Tuple[Engine, List[Event]]:
    """Events with times in seconds since `start`; every spec topic is watched from `start`.

    Messages on `node_topics` are the monitor's recorded node samples (JSON with node, alive,
    cpu, memory), fed to the engine as samples.
    """
    node_topics = set(node_topics)
    engine = Engine(spec, 0.0, origin=start)  # times run from 0; header stamps stay absolute
    events = engine.evaluate_all(0.0)
    extend, on_messages = events.extend, engine.on_messages
    period = 1.0 / rate
    next_tick = period
    batch: List[Tuple[str, Optional[Any]]] = []
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
                batch = []
            ticks_until(t, inclusive=False)
            sample = _node_sample(msg)
            if sample is not None:
                # at the instant the monitor took it (recorded in the sample), as the live engine did
                at = max(min(t, sample[4] - start), engine.store.now) if sample[4] is not None else t
                extend(engine.on_node_sample(sample[0], at, *sample[1:4]))
            batch_time = t  # the ticks before t are done
            continue
        if t != batch_time:
            if batch:
                extend(on_messages(batch_time, batch))
                batch = []
            if next_tick < t:
                ticks_until(t, inclusive=False)
            batch_time = t
        batch.append((topic, msg))
    if batch:
        extend(on_messages(batch_time, batch))
    ticks_until(end - start, inclusive=True)
    extend(engine.advance(end - start))
    return engine, events


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
