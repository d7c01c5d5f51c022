"""Keeps the latch state file in step with what is latched: behaviours of the running spec, latched
behaviours a reload removed, the overload and data-error fail-safes, and latches restored from a
previous run (held until ~reset). See latches.py for the file and why it exists.

Runs on the engine's thread (its calls come from the event handler, the tick, reset and reload).
"""
from __future__ import annotations

from typing import Any, Callable, Dict, List, Sequence

from ..engine import Engine, Event
from .base import Context
from .latches import Latch, LatchFile, holders, load, other_masters
from .status import ELSEWHERE, HELD

Log = Callable[[str, str], None]
Report = Callable[[Dict[str, Any]], None]
RESTORED = "rubass-restored"  # the runners' identity for a restored latch: (RESTORED, holder)


RETRY = 1.0  # s between tries to write a latch state that could not be written


def behaviour_holder(b: Any) -> str:
    return f"behaviour {b.index} (line {b.span.line})"


class LatchKeeper:
    def __init__(self, file: LatchFile, log: Log, report: Report) -> None:
        self.file = file
        self.log = log
        self.report = report
        self.restored: List[Latch] = []
        self.problems: List[str] = []  # what was wrong with the file at start
        self.elsewhere: List[str] = []  # files of this node for other masters holding latches, until ~reset
        self._retried = float("-inf")  # when a failed write was last tried again (retry)

    # -- start ---------------------------------------------------------------------------
    def restore(self, actions: Dict[str, Any], runners: Dict[str, Any], now: float) -> None:
        """Before the first tick: start again every latched action the previous run held."""
        if self.file.path is None:
            return
        latches, self.problems = load(self.file.path, {n: bool(a.latch) for n, a in actions.items()})
        self.elsewhere = other_masters(self.file.path)  # this master spelt otherwise? WARN until ~reset
        for other in self.elsewhere:
            self.log("warn", f"{other} holds a latched stop of this node under another master's name; this run's "
                             f"state file {self.file.path} holds none. If that is this robot's master spelt "
                             f"otherwise, restart with the old spelling or ~state_file:={other} (docs/actions.md)")
        for p in self.problems:
            self.log("error", p)
        for latch in latches:
            names = [a for a in latch.actions if a in runners]
            for name in names:
                runners[name].submit("start", self._ctx(latch, now))
            self.restored.append(latch)
            self.log("error", f"latched before the monitor stopped ({latch.holder}): {', '.join(latch.actions)} "
                              f"active again until ~reset (ISO 3691-4: no automatic restart after a protective stop)")
            self.report({"time": now, "event": "start", "behaviour": 0, "line": 0, "actions": list(latch.actions),
                         "rules": [], "cause": f"restored: {latch.holder}", "latency_ms": None})

    @staticmethod
    def _ctx(latch: Latch, now: float) -> Context:
        return Context(0, 0, (), (), now, (RESTORED, latch.holder))

    # -- state ---------------------------------------------------------------------------
    def changes(self, engine: Engine, events: Sequence[Event]) -> bool:
        """Whether these events start or release a latched behaviour (the file must follow)."""
        bs = engine.spec.behaviours
        return any(e.kind in ("start", "release") and bs[e.behaviour - 1].latched for e in events)

    def save(self, engine: Engine, orphans: Sequence[Any], fail_safes: Sequence[Sequence[str]]) -> None:
        """Write the state now: call it before a latched action is dispatched."""
        if not self.file.save(self._latches(engine, orphans, fail_safes)):
            self.log("error", f"{self.file.error}: a latched stop would not survive the monitor's restart")

    def retry(self, engine: Engine, orphans: Sequence[Any], fail_safes: Sequence[Sequence[str]], now: float) -> None:
        """At a tick, while the last write failed (a full disk): write again at most every RETRY seconds,
        so that once the disk is freed a latched stop is in the file before a restart needs it."""
        if not self.file.error or 0.0 <= now - self._retried < RETRY:  # (time that went back: now)
            return
        self._retried, was = now, self.file.error
        if self.file.save(self._latches(engine, orphans, fail_safes)):
            self.log("info", f"latch state written again (it could not be: {was})")

    def _latches(self, engine: Engine, orphans: Sequence[Any], fail_safes: Sequence[Sequence[str]]) -> List[Latch]:
        spec = engine.spec
        items = []
        for index in engine.active_behaviours():
            b = spec.behaviours[index - 1]
            items.append((behaviour_holder(b), [a.name for a in b.actions if a.action.latch]))
        for b, _key in orphans:
            items.append((behaviour_holder(b) + " of a replaced spec", [a.name for a in b.actions if a.action.latch]))
        for i, names in enumerate(fail_safes):
            items.append((f"fail-safe {i}", [a for a in names if a in spec.actions and spec.actions[a].latch]))
        items += [(r.holder, r.actions) for r in self.restored]
        return holders(items)

    def reset(self, runners: Dict[str, Any], now: float) -> int:
        """~reset: release the restored latches; how many there were."""
        n = len(self.restored)
        for latch in self.restored:
            for name in latch.actions:
                if name in runners:
                    runners[name].submit("release", self._ctx(latch, now))
            self.report({"time": now, "event": "release", "behaviour": 0, "line": 0, "actions": list(latch.actions),
                         "rules": [], "cause": "reset service", "latency_ms": None})
        self.restored = []
        self.problems = []  # the file is rewritten from the state now held
        self.elsewhere = []  # acknowledged
        return n

    def status(self) -> Dict[str, str]:
        out: Dict[str, str] = {}
        if self.restored:
            out[HELD[1]] = "; ".join(f"{', '.join(r.actions)} ({r.holder})"
                                                                for r in self.restored)
        errors = self.problems + ([self.file.error] if self.file.error else [])
        if errors:
            out["latch state error"] = "; ".join(errors)
        out["latch state file"] = self.file.path or "off (~state_file: false)"
        if self.elsewhere:
            out[ELSEWHERE] = ", ".join(self.elsewhere)
        return out
