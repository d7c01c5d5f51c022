"""Failing safe when the monitor cannot keep up.

A monitor whose engine queue is full drops messages, and a dropped message may be the one
that shows a violation; a monitor that cannot keep up without dropping sees its messages late:
they wait in the sockets' buffers (its receiving thread reads late) or in the engine's queue
(the engine evaluates late), `behind` seconds, and the robot's state its rules see is that old.
With `~overload_actions` set (e.g. `[stop]`), the monitor runs those actions as soon as a
message is dropped or seen `LATE` or later, and releases them once neither has happened for
`calm` seconds (a latched action stays until `~reset`). Checked on every engine tick.
"""
from __future__ import annotations

from typing import Any, Callable, Dict, Optional, Sequence, Tuple

from .failsafe import FailSafe, Log, Report

LATE = 0.5  # s: a message that waited this long before the monitor evaluated it: it cannot keep up
SOCKETS, QUEUE = "sockets", "queue"  # where late messages waited


def lateness(behind: float, where: str) -> Tuple[str, str]:
    """What is late and where it waited, for the log and the status: ('its topics are read 1.00 s late',
    "their messages wait in the sockets' buffers"), or the engine queue's pair."""
    if where == QUEUE:
        return f"its messages are evaluated {behind:.2f} s late", "they wait in the engine's queue"
    return f"its topics are read {behind:.2f} s late", "their messages wait in the sockets' buffers"


def late_status(read: float, waited: float) -> str:
    """The status's `read late`: 'no', or how late and where, the later of the receiver's reads (`read`)
    and the engine queue's waits (`waited`), when that is LATE or later."""
    behind = max(read, waited)
    if behind < LATE:
        return "no"
    where = "in the engine's queue" if waited > read else "in the sockets' buffers"
    return f"{behind:.2f} s (messages waited that long {where}: the monitor cannot keep up)"


class OverloadGuard(FailSafe):
    key = ("rubass-overload", 0)
    rule = "monitor.overloaded"
    cause = "overload"

    def __init__(self, actions: Sequence[str], calm: float, log: Log, report: Report) -> None:
        super().__init__(actions, log, report)
        self.calm = calm
        self._seen = 0  # drops already accounted for
        self._last_drop = 0.0  # the latest drop or late read
        self.reason = "dropping messages"  # what started the actions, for the status

    def released_text(self, why: str) -> str:
        return f"overload over ({why}): releasing {', '.join(self.actions)}"

    def check(self, dropped: int, now: float, runners: Dict[str, Any], latched: Callable[[str], bool],
              by_topic: Optional[Dict[str, int]] = None, behind: float = 0.0, where: str = SOCKETS) -> None:
        """On the engine's thread, at each tick: start on new drops or late messages, hold, release
        when calm. by_topic: messages dropped so far per topic, named in the log; behind: how late
        the monitor saw its messages since the last tick (s; Receiver.take_behind, or
        EngineLoop.take_waited), `where` they waited (SOCKETS or QUEUE)."""
        late = behind >= LATE
        if dropped > self._seen or late:
            new, self._seen, self._last_drop = dropped - self._seen, dropped, now
            if not self.active and self.actions:
                self.active = True
                what, waits = lateness(behind, where)
                queued = where == QUEUE
                self.reason = "dropping messages" if new else \
                    f"{'evaluating its messages' if queued else 'reading its topics'} {behind:.2f} s late"
                why = (f"{new} messages dropped (the engine's queue is full{_topics(by_topic)}; the newest message "
                       f"of each topic is kept and evaluated)" if new else
                       f"{what} ({waits}: it cannot keep up; " +
                       ("its actions come that late)" if queued else "a late message is evaluated as if it came now)"))
                self.log("error", f"overloaded: {why}: running the fail-safe actions {', '.join(self.actions)} "
                                  f"(~overload_actions)")
                self._send("start", now, runners)
                return
        if not self.active:
            return
        if now - self._last_drop >= self.calm and not any(latched(a) for a in self.actions):
            self.release(now, runners, f"no message dropped or read {LATE:g} s late for {self.calm:g} s")
        else:
            self._send("hold", now, runners)

    def would_start(self, dropped: int, behind: float = 0.0) -> bool:
        """Whether check() with this drop count and lateness starts the fail-safe actions."""
        return (dropped > self._seen or behind >= LATE) and not self.active and bool(self.actions)

    def reset(self, now: float, runners: Dict[str, Any]) -> bool:
        """~reset: release latched fail-safe actions once calm; whether it did."""
        if self.active and now - self._last_drop >= self.calm:
            self.release(now, runners, "reset")
            return True
        return False



def _topics(by_topic: Optional[Dict[str, int]]) -> str:
    """'; dropped so far: /scan 800, /odom 12' (the five topics that lost most)."""
    if not by_topic:
        return ""
    top = sorted(by_topic.items(), key=lambda kv: -kv[1])[:5]
    return "; dropped so far: " + ", ".join(f"{t} {n}" for t, n in top) + (", …" if len(by_topic) > 5 else "")
