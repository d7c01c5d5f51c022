"""What the engine answers: events (a behaviour's start, hold or release, a rule's new value),
and the order of one instant's events."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, List, Optional, Tuple

from .explain import Witness


@dataclass(frozen=True)
class Event:
    """A change: a behaviour's start/hold/release, or a rule's new value ('rule')."""

    time: float
    kind: str
    behaviour: int = 0  # 1-based, in file order
    rule: str = ""
    value: Any = None
    actions: Tuple[str, ...] = ()
    line: int = 0
    name: str = ""  # the behaviour's name (§14), "" when unnamed
    witness: Optional[Witness] = None  # at a start: the true rules and the values they read (explain.py)


def starts_first(events: List[Event]) -> List[Event]:
    """The events of each instant with its starts before its releases, so that an action one
    behaviour hands to another in one instant (on a message, or at a deadline) gains its new holder
    before it loses the old one: it stays on, no `on_release`, no second start. A behaviour that
    releases and starts again in one instant keeps that order."""
    out: List[Event] = []
    i, n = 0, len(events)
    while i < n:
        t, j = events[i].time, i + 1
        while j < n and events[j].time == t:
            j += 1
        group = events[i:j]
        if len(group) > 1 and any(e.kind == "release" for e in group):
            keep, late = [], []
            for k, e in enumerate(group):
                again = e.kind == "release" and any(g.kind == "start" and g.behaviour == e.behaviour
                                                    for g in group[k + 1:])
                (late if e.kind == "release" and not again else keep).append(e)
            group = keep + late
        out += group
        i = j
    return out
