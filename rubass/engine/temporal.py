"""Run-time state of temporal operators: one object per `for` node, owned by the engine."""
from __future__ import annotations

from typing import Any, Callable, Optional

from .values import UNKNOWN


class ForTimer:
    """`E for T`: true once E has been true at every evaluation for T (LANGUAGE.md §6).

    `since` is the time of the evaluation at which E turned true; any false or unknown
    evaluation clears it. While E is true but for less than T the value is false; when a
    count starts, `notify` tells the engine the exact instant it will turn true.
    """

    __slots__ = ("duration", "since", "notify")

    def __init__(self, duration: float) -> None:
        self.duration = duration
        self.since: Optional[float] = None
        # called once when a count starts: notify(due, timer, since); the engine schedules it
        self.notify: Optional[Callable[[float, "ForTimer", float], None]] = None

    def update(self, now: float, value: Any) -> Any:
        if value is True:
            if self.since is None:
                self.since = now
                if self.duration > 0 and self.notify is not None:
                    self.notify(now + self.duration, self, now)
            return now >= self.since + self.duration
        self.since = None
        return UNKNOWN if value is UNKNOWN else False

    def reset(self) -> None:
        self.since = None
