"""Run-time state of temporal operators: one object per `for` node, owned by the engine."""
from __future__ import annotations

from typing import Any, Optional

from .values import UNKNOWN


class ForTimer:
    """`E for T`: true once E has been true at every evaluation for T (LANGUAGE.md §6).

    `since` is the time of the evaluation at which E turned true; any false or unknown
    evaluation clears it. While E is true but for less than T the value is false and
    `deadline` is the exact instant it will turn true.
    """

    __slots__ = ("duration", "since")

    def __init__(self, duration: float) -> None:
        self.duration = duration
        self.since: Optional[float] = None

    def update(self, now: float, value: Any) -> Any:
        if value is True:
            if self.since is None:
                self.since = now
            return now >= self.since + self.duration
        self.since = None
        return UNKNOWN if value is UNKNOWN else False

    def deadline(self, now: float, strict: bool = True) -> Optional[float]:
        """When this timer turns true if nothing changes: after now (strict) or at now, or None."""
        if self.since is None:
            return None
        due = self.since + self.duration
        return due if (due > now if strict else due >= now) else None

    def reset(self) -> None:
        self.since = None
