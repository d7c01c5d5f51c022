"""Stateful operators (LANGUAGE.md §6, §10): one small runtime object per `for`, `within` and
`latch` node, owned by the engine, all with one protocol (as rtamt's operators):

    update(now, *inputs) -> value     the operator's value at `now`, given its inputs there
    deadline() -> float | None        the next instant its value changes by itself
    reset()                           back to the state before the first evaluation
    snapshot() / restore(state)       carry the state across a live reload

The engine schedules what `deadline()` announces and never reads an operator's internals.
Evaluating twice at one instant is harmless: each operator keeps its state before that instant.
"""
from __future__ import annotations

from typing import Any, Optional

from .values import UNKNOWN, k_and, k_not, k_or


class Operator:
    """The protocol; subclasses keep their state in __slots__."""

    __slots__ = ()

    def deadline(self) -> Optional[float]:
        return None

    def reset(self) -> None:
        raise NotImplementedError

    def snapshot(self) -> Any:
        return tuple(getattr(self, s) for s in self.__slots__ if s not in ("duration",))

    def restore(self, state: Any) -> None:
        for name, value in zip((s for s in self.__slots__ if s != "duration"), state):
            setattr(self, name, value)


class ForOp(Operator):
    """`E for T`: true once E has been true at every evaluation for T (§6).

    `since` is the instant of the evaluation at which E turned true; any false or unknown
    evaluation clears it. Its deadline is since + T, while that is still ahead.
    """

    __slots__ = ("duration", "since", "now")

    def __init__(self, duration: float) -> None:
        self.duration = duration
        self.since: Optional[float] = None
        self.now = float("-inf")

    def update(self, now: float, value: Any) -> Any:
        self.now = now
        if value is True:
            if self.since is None:
                self.since = now
            return now >= self.since + self.duration
        self.since = None
        return UNKNOWN if value is UNKNOWN else False

    def deadline(self) -> Optional[float]:
        if self.since is None or self.duration <= 0:
            return None
        due = self.since + self.duration
        return due if due > self.now else None

    def reset(self) -> None:
        self.since = None


class WithinOp(Operator):
    """`E within T`: E was true at some instant of (t − T, t] (§10).

    E is piecewise constant between evaluations, so it is enough to keep the instant E last
    stopped being true (`true_end`) and stopped being unknown (`unknown_end`); time before the
    first evaluation counts as unknown (`unknown_end` starts there).
    """

    __slots__ = ("duration", "state", "true_end", "unknown_end", "now")

    def __init__(self, duration: float) -> None:
        self.duration = duration
        self.reset()

    def reset(self) -> None:
        self.state: Any = None  # E's value at the last evaluation; None before the first
        self.true_end: Optional[float] = None
        self.unknown_end: Optional[float] = None
        self.now = float("-inf")

    def update(self, now: float, value: Any) -> Any:
        if self.state is None:
            self.unknown_end = now  # before the first evaluation: unknown
        elif self.state is True and value is not True:
            self.true_end = now
        elif self.state is UNKNOWN and value is not UNKNOWN:
            self.unknown_end = now
        self.state = value
        self.now = now
        if value is True:
            return True
        if self.true_end is not None and now < self.true_end + self.duration:
            return True
        if value is UNKNOWN or (self.unknown_end is not None and now < self.unknown_end + self.duration):
            return UNKNOWN
        return False

    def deadline(self) -> Optional[float]:
        due = [t + self.duration for t in (self.true_end, self.unknown_end)
               if t is not None and t + self.duration > self.now]
        return min(due) if due else None


class LatchOp(Operator):
    """latch(SET, RESET) = SET or (latch(t⁻) and not RESET), false before the first evaluation (§10)."""

    __slots__ = ("before", "value", "at")

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        self.before: Any = False  # the latch's value before the instant `at`
        self.value: Any = False
        self.at = float("-inf")

    def update(self, now: float, set_: Any, reset: Any) -> Any:
        if now > self.at:
            self.before, self.at = self.value, now
        self.value = k_or(set_, k_and(self.before, k_not(reset)))
        return self.value
