"""Actions the monitor runs on its own account, not for a behaviour (~overload_actions,
~error_actions): started, held and released through the runners like a behaviour's, under one
identity of their own, and reported on ~events."""
from __future__ import annotations

from typing import Any, Callable, Dict, Sequence, Tuple

from .base import Context

Log = Callable[[str, str], None]
Report = Callable[[Dict[str, Any]], None]


class FailSafe:
    """The shared half of the overload and data-error guards."""

    key: Tuple[str, int]  # the runners' identity for this pseudo-behaviour
    rule: str  # how ~events names its cause, e.g. 'monitor.overloaded'
    cause: str

    def __init__(self, actions: Sequence[str], log: Log, report: Report) -> None:
        self.actions, self.log, self.report = list(actions), log, report
        self.active = False

    def released_text(self, why: str) -> str:
        return f"{why}: releasing {', '.join(self.actions)}"

    def release(self, now: float, runners: Dict[str, Any], why: str) -> None:
        if self.active:
            self.active = False
            self.log("warn", self.released_text(why))
            self._send("release", now, runners)

    def _send(self, kind: str, now: float, runners: Dict[str, Any]) -> None:
        for name in self.actions:
            runner = runners.get(name)
            if runner is not None:
                runner.submit(kind, Context(0, 0, (self.rule,), (), now, self.key))
        if kind != "hold":
            self.report({"time": now, "event": kind, "behaviour": 0, "line": 0, "actions": self.actions,
                         "rules": [self.rule], "cause": self.cause, "latency_ms": None})
