"""Driving the engine over recorded messages: each at its time, ticks in between, and
messages that share a timestamp evaluated together. Pure: the recording is any iterable."""
from __future__ import annotations

from typing import Any, Iterable, List, Optional, Tuple

from ..engine import Engine, Event
from ..lang.model import CheckedSpec


def replay(spec: CheckedSpec, messages: Iterable[Tuple[float, str, Optional[Any]]], start: float, end: float,
           rate: float = 50.0) -> Tuple[Engine, List[Event]]:
    """Events with times in seconds since `start`; every spec topic is watched from `start`."""
    engine = Engine(spec, 0.0)
    events = engine.evaluate_all(0.0)
    period = 1.0 / rate
    next_tick = period
    batch: List[Tuple[str, Optional[Any]]] = []
    batch_time = 0.0

    def flush() -> None:
        if batch:
            events.extend(engine.on_messages(batch_time, batch))
            batch.clear()

    def ticks_until(t: float, inclusive: bool) -> None:
        nonlocal next_tick
        while next_tick < t or (inclusive and next_tick == t):
            events.extend(engine.on_tick(next_tick))
            next_tick = round((next_tick + period) / period) * period  # no drift over long bags

    for stamp, topic, msg in messages:
        t = stamp - start
        if batch and t != batch_time:
            flush()
        if not batch:
            ticks_until(t, inclusive=False)
            batch_time = t
        batch.append((topic, msg))
    flush()
    ticks_until(end - start, inclusive=True)
    events.extend(engine.advance(end - start))
    return engine, events
