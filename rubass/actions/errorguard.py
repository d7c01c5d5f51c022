"""Data errors are loud: while a field cannot be read as the spec needs (an array used as a
number, a missing field, a message that cannot be deserialised), the rules that read it are
unknown, and a safety rule that is unknown protects nothing. With `~error_actions` set (e.g.
`[stop]`), the monitor runs those actions while such an error lasts, and releases them when it
is gone (a latched action stays until ~reset). Checked on every engine tick.
"""
from __future__ import annotations

from typing import Any, Callable, Dict, List, Sequence

from .failsafe import FailSafe, Log, Report


class ErrorGuard(FailSafe):
    key = ("rubass-data-error", 0)
    rule = "monitor.data_error"
    cause = "data error"

    def __init__(self, actions: Sequence[str], log: Log, report: Report) -> None:
        super().__init__(actions, log, report)
        self.errors: List[str] = []

    def released_text(self, why: str) -> str:
        return f"{why}: releasing {', '.join(self.actions)} (~error_actions)"

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

    def reset(self, now: float, runners: Dict[str, Any]) -> bool:
        """~reset: release latched error actions once no error is left; whether it did."""
        if self.active and not self.errors:
            self.release(now, runners, "reset")
            return True
        return False
