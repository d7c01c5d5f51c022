"""The message types on one watched topic, per publisher.

rospy.AnyMsg accepts publishers of any type, and ROS does not stop two nodes from publishing
two types on one topic (a std_msgs/String beside a std_msgs/Float64 on /speed). Each message's
connection header says its type. A type change (the only publisher restarted with another
type) is reported once and its fields are checked again; two types at once are a data error
for as long as publishers of both are connected: /diagnostics says ERROR naming the topic and
both types, `~error_actions` run (held, not flapping), it is logged once (then at most once per
LOG_EVERY seconds), and only the messages of a type whose fields the spec can read are
evaluated: a real violation in them is still stopped, the other type's messages change nothing.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Optional, Set, Tuple

WINDOW = 1.0  # s: without a readable connection list, a publisher is present while it sent within this
RECHECK = 0.25  # s: while two types publish, how often a message of the current type looks again
LOG_EVERY = 10.0  # s: a conflict that ends and starts again is logged at most this often per topic
MAX_CALLERS = 32  # publishers remembered per topic beyond those that sent within WINDOW

Log = Callable[[str, str], None]


@dataclass
class Kind:
    """One message type seen on a topic."""

    type: str
    md5: str
    cls: Any  # None: the type cannot be loaded
    problems: List[str]  # what the spec's fields cannot read in this type
    last: float = 0.0  # wall time of its newest message
    unreadable: bool = False  # none of the spec's fields can be read in it: its messages are no data

    @property
    def fits(self) -> bool:
        return self.cls is not None and not self.problems

    def label(self, callers: Dict[str, Tuple[str, float]]) -> str:
        who = ", ".join(sorted(c for c, (md5, _) in callers.items() if c and md5 == self.md5))
        return f"{self.type} (from {who})" if who else self.type


def present_md5s(subscriber: Any, callers: Dict[str, Any], now: float) -> Set[str]:
    """The types that publishers connected now send: from the subscription's connections, or,
    when they cannot be read, from each publisher's newest message within WINDOW."""
    conns = getattr(getattr(subscriber, "impl", None), "connections", None) if subscriber is not None else None
    if conns is not None:
        found = {(getattr(c, "header", None) or {}).get("md5sum") for c in list(conns)}
        return {m for m in found if m}
    return {md5 for md5, last in callers.values() if now - last <= WINDOW}


def conflict_text(present: List[Kind], callers: Dict[str, Tuple[str, float]]) -> str:
    fitting = [k.type for k in present if k.fits]
    labels = " and ".join(k.label(callers) for k in sorted(present, key=lambda k: k.type))
    read = (f"only its {' and '.join(fitting)} messages are evaluated" if fitting else
            "the spec's fields fit none of them: its values are unknown")
    return f"publishers of {len(present)} types at once: {labels}; {read}"


def admit(state: Any, header: Dict[str, str], now: float, new_kind: Callable[[Any, Dict[str, str]], Kind],
          log: Log) -> bool:
    """A message with this connection header on `state`'s topic (under the watcher's type lock):
    whether it is evaluated. Keeps state.type/md5/cls/errors on the type evaluated, and
    state.mixed on the conflict text while publishers of two types are connected."""
    md5 = header.get("md5sum", "")
    kind = state.kinds.get(md5)
    if kind is None:
        kind = state.kinds[md5] = new_kind(state, header)
    kind.last = now
    caller = header.get("callerid", "")
    state.callers[caller] = (md5, now)
    if len(state.callers) > MAX_CALLERS:  # anonymous publishers come and go: keep the recent ones
        state.callers = {c: v for c, v in state.callers.items() if now - v[1] <= WINDOW or c == caller}
    state.checked = now
    live = present_md5s(state.subscriber, state.callers, now) | {md5}
    present = [k for k in state.kinds.values() if k.md5 in live]
    if len(present) <= 1:
        if state.mixed is not None:
            log("info", over(state, kind.type))
            state.mixed = None
        for m in [m for m in state.kinds if m != md5]:
            del state.kinds[m]  # gone: if it comes back, it is a change again
        state.callers = {c: v for c, v in state.callers.items() if v[0] == md5}
        if md5 != state.md5:
            adopt(state, kind, log, change=True)
        return True
    text = conflict_text(present, state.callers)
    if state.mixed != text:
        if state.mixed is None and now - state.mixed_logged >= LOG_EVERY:
            state.mixed_logged = now
            log("error", f"topic {state.resolved}: DATA ERROR: {text}")
        state.mixed = text
    if kind.fits or not any(k.fits for k in present):
        if md5 != state.md5:
            adopt(state, kind, log, change=False)
        return True
    return False


def refresh(state: Any, now: float, log: Log) -> Optional[str]:
    """Whether the conflict on `state` still holds (both publishers may have gone quiet or away
    since its last message): the conflict text or None. Under the watcher's type lock."""
    if state.mixed is None:
        return None
    live = present_md5s(state.subscriber, state.callers, now)
    present = [k for k in state.kinds.values() if k.md5 in live]
    if len(present) <= 1:
        log("info", over(state, present[0].type if present else ""))
        state.mixed = None
        if present and present[0].md5 != state.md5:  # the one left is what is read now (its errors at once)
            adopt(state, present[0], log, change=True)
        for m in [m for m in state.kinds if m != state.md5]:
            del state.kinds[m]
        return None
    state.mixed = conflict_text(present, state.callers)
    return state.mixed


def over(state: Any, left: str) -> str:
    return (f"topic {state.resolved}: {f'only {left} is published now' if left else 'no publisher is left'}: "
            f"its data error of two types at once is over")


def adopt(state: Any, kind: Kind, log: Log, change: bool) -> None:
    """Evaluate `kind`'s messages from now on; a change of the only type is logged and kept."""
    old = state.type
    state.decoder = (kind.md5, kind.cls, kind.type, kind.unreadable)  # one value: read by callbacks without the lock
    state.errors = ([] if kind.cls is not None else [f"cannot load message type {kind.type}"]) + list(kind.problems)
    if change and old and old != kind.type:  # a warning when the spec reads the new type (docs/monitor.md: no error)
        log("error" if state.errors else "warn", f"topic {state.resolved} changed type from {old} to {kind.type}")
        state.errors.append(f"changed type from {old} to {kind.type}")
