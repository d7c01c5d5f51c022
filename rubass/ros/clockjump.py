"""When ROS time jumps back (a simulator reset with use_sim_time, or the wall clock stepped back):
every window starts again, and no action that protects the robot is dropped meanwhile.

Times the engine holds (`for` starts, arrivals, deadlines) belong to the old timeline: kept, a
`for` that started at 112 s would only fire once the new clock passes 113 s. So the engine is
built again from the same spec at the new time (`for`, `age` and `frequency` count from the
jump, as at start-up), and what was active is held across: a latched behaviour as after a
reload (until ~reset), any other for as long as its condition needs to become true again (its
longest `for`, `age` limit or `frequency` window, plus 0.5 s). If the rebuilt engine starts it
again meanwhile, it owns it (same identity: no second start); otherwise it is released then.
Runs on the engine's thread (the loop's clock-jump hook and the tick).
"""
from __future__ import annotations

from typing import Any, Callable, List, Tuple

from ..engine import Engine, Event
from ..lang import ast

Log = Callable[[str, str], None]
MARGIN = 0.5  # seconds beyond the longest time a condition needs to become true again


def horizon(spec: Any) -> float:
    """How long after a restart a persisting violation may take to be seen again: the longest
    `for`, `within` or `frequency` window, or limit an `age`/`stamp_age` is compared with."""
    longest = 0.0
    exprs = [r.expr for r in spec.rules] + [b.cond for b in spec.behaviours]
    for expr in exprs:
        for e in ast.walk(expr):
            times: List[Any] = []
            if isinstance(e, (ast.For, ast.Within)):
                times.append(getattr(e.duration, "value", None))
            elif isinstance(e, ast.Frequency):
                times.append(e.window)
            elif isinstance(e, ast.Binary) and e.op in ("<", "<=", ">", ">="):
                for side, other in ((e.left, e.right), (e.right, e.left)):
                    if any(isinstance(x, (ast.Age, ast.StampAge)) for x in ast.walk(side)):
                        times.append(getattr(other, "value", None))
            longest = max([longest] + [t for t in times if isinstance(t, float) and 0.0 < t < 3600.0])
    return longest + MARGIN


class ClockJump:
    def __init__(self, dispatcher: Any, log: Log, after: Callable[[Engine], None]) -> None:
        self.dispatcher = dispatcher
        self.log = log
        self.after = after  # called with the new engine (the latch state follows)
        self.carried: List[Tuple[Any, Any, float]] = []  # (behaviour, identity, release at)
        self.jumps = 0

    def __call__(self, old: Engine, now: float) -> Tuple[Engine, List[Event]]:
        """The loop's hook: the engine rebuilt at `now`, and its first evaluation's events."""
        self.jumps += 1
        new = Engine(old.spec, now)
        keys = self.dispatcher.keys_of(old.spec)
        until = now + horizon(old.spec)
        held = []
        events: List[Event] = []
        for holder, actions in old.outside_holders().items():  # restored latches and earlier carries
            events += new.hold_actions(actions, holder, now)
        for index in old.active_behaviours():
            b = old.spec.behaviours[index - 1]
            held.append(str(index))
            actions = [a.name for a in b.actions]
            if b.latched:
                self.dispatcher.orphans.append((b, keys[index]))
                events += new.hold_actions(actions, f"{b.label} (latched before a clock jump)", now)
            else:
                self.carried.append((b, keys[index], until))
                events += new.hold_actions(actions, _carried(b), now)  # active() stays true meanwhile
        self.log("warn", f"ROS time jumped back from {old.store.now:.3f} s to {now:.3f} s (a simulator reset?): "
                         f"every `for`, `age` and `frequency` window starts again from now"
                         + (f"; active behaviours {', '.join(held)} stay active (latched ones until ~reset)"
                            if held else ""))
        events += new.evaluate_all(now)
        self.after(new)
        return new, events

    def check(self, engine: Engine, now: float) -> None:
        """At each tick: release carried behaviours the rebuilt engine did not take over in time."""
        if not self.carried:
            return
        active = set(engine.active_behaviours())
        keep = []
        for b, key, until in self.carried:
            if b.index in active and engine.spec.behaviours[b.index - 1] is b:
                self.dispatcher.handle(engine, engine.release_holder(_carried(b), now), "clock jump")
                continue  # the engine holds it again, under the same identity
            if now >= until or now < until - 3600.0:
                self.dispatcher.release(b, key, now)
                self.dispatcher.handle(engine, engine.release_holder(_carried(b), now), "clock jump")
            else:
                keep.append((b, key, until))
        self.carried = keep


def _carried(b: Any) -> str:
    return f"{b.label} (carried across a clock jump)"
