"""Data errors are loud: while a field cannot be read as the spec needs (an array used as a
number, a missing field, a message that cannot be deserialised), the rules that read it are
unknown, and a safety rule that is unknown protects nothing. With `~error_actions` set (e.g.
`[stop]`), the monitor runs those actions while such an error lasts, and releases them when it
is gone (a latched action stays until ~reset). Checked on every engine tick.
"""
from __future__ import annotations

from typing import Any, Callable, Dict, List, Sequence

from .base import Context

KEY = ("rubass-data-error", 0)  # the runners' identity for this pseudo-behaviour
Log = Callable[[str, str], None]
Report = Callable[[Dict[str, Any]], None]


class ErrorGuard:
    def __init__(self, actions: Sequence[str], log: Log, report: Report) -> None:
        self.actions, self.log, self.report = list(actions), log, report
        self.active = False
        self.errors: List[str] = []

    def check(self, errors: List[str], now: float, runners: Dict[str, Any], latched: Callable[[str], bool]) -> None:
        """On the engine's thread, at each tick, with the data errors that exist now."""
        self.errors = errors
        if errors and not self.active and self.actions:
            self.active = True
            self.log("error", f"data error ({errors[0]}{' and more' if len(errors) > 1 else ''}): running "
                              f"{', '.join(self.actions)} (~error_actions) while it lasts")
            self._send("start", now, runners)
        elif self.active and not errors and not any(latched(a) for a in self.actions):
            self.release(now, runners, "the data error is gone")
        elif self.active:
            self._send("hold", now, runners)

    def release(self, now: float, runners: Dict[str, Any], why: str) -> None:
        if self.active:
            self.active = False
            self.log("warn", f"{why}: releasing {', '.join(self.actions)} (~error_actions)")
            self._send("release", now, runners)

    def reset(self, now: float, runners: Dict[str, Any]) -> bool:
        """~reset: release latched error actions once no error is left; whether it did."""
        if self.active and not self.errors:
            self.release(now, runners, "reset")
            return True
        return False

    def _send(self, kind: str, now: float, runners: Dict[str, Any]) -> None:
        for name in self.actions:
            runner = runners.get(name)
            if runner is not None:
                runner.submit(kind, Context(0, 0, ("monitor.data_error",), (), now, KEY))
        if kind != "hold":
            self.report({"time": now, "event": kind, "behaviour": 0, "line": 0, "actions": self.actions,
                         "rules": ["monitor.data_error"], "cause": "data error", "latency_ms": None})
