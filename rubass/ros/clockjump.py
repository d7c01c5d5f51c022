"""When ROS time jumps back (a simulator reset with use_sim_time, or the wall clock stepped back):
every window starts again, and no action that protects the robot is dropped meanwhile.

Times the engine holds (`for` starts, arrivals, deadlines) belong to the old timeline: kept, a
`for` that started at 112 s would only fire once the new clock passes 113 s. So the engine is
built again from the same spec at the new time (`for`, `age` and `frequency` count from the
jump, as at start-up), and what was active is held across: a latched behaviour as after a
reload (until ~reset), any other for as long as its condition needs to become true again (its
longest `for`, `age` limit or `frequency` window, plus 0.5 s). If the rebuilt engine starts it
again meanwhile, it owns it (same identity): that start is no new start, its actions and ~events
see none (`take_over`); otherwise it is released then, and ~events reports that release, so
starts and releases stay paired. Runs on the engine's thread (the loop's clock-jump hook and the tick).
"""
from __future__ import annotations

import dataclasses
import threading
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
        self.carried: List[Tuple[Any, Any, float, str]] = []  # (behaviour, identity, release at, holder)
        self.latched: List[Tuple[Any, Any]] = []  # (behaviour, identity): latched, held until ~reset
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
                self.latched.append((b, keys[index]))
                events += new.hold_actions(actions, _latched(b), now)
            else:
                self.carry(b, keys[index], until, _carried(b))
                events += new.hold_actions(actions, _carried(b), now)  # active() stays true meanwhile
        self.log("warn", f"ROS time jumped back from {old.store.now:.3f} s to {now:.3f} s (a simulator reset?): "
                         f"every `for`, `age` and `frequency` window starts again from now"
                         + (f"; active behaviours {', '.join(held)} stay active (latched ones until ~reset)"
                            if held else ""))
        events += new.evaluate_all(now)
        self.after(new)
        return new, events

    def carry(self, b: Any, key: Any, until: float, holder: str) -> None:
        """Hold `b` (its actions held in the engine by `holder`) until `until`, or until the engine
        starts it again under the same identity (take_over): a clock jump's, or a reload's whose
        edit lost its condition's history (rubass/ros/reloading.py)."""
        self.carried.append((b, key, until, holder))

    def take_over(self, engine: Engine, events: List[Event]) -> List[Event]:
        """Before dispatch: the start of a behaviour held across a jump (same identity) is no new
        start: it becomes a hold, and the engine owns it from now (the hold across the jump ends)."""
        if not (self.carried or self.latched) or not any(e.kind == "start" for e in events):
            return events
        keys = self.dispatcher.keys_of(engine.spec)
        out: List[Event] = []
        for e in events:
            key = keys.get(e.behaviour) if e.kind == "start" else None
            carried = [c for c in self.carried if c[1] == key] if key is not None else []
            latched = [c for c in self.latched if c[1] == key] if key is not None else []
            if not (carried or latched):
                out.append(e)
                continue
            out.append(dataclasses.replace(e, kind="hold", witness=None))
            more: List[Event] = []
            for c in carried:
                self.carried.remove(c)
                more += engine.release_holder(c[3], e.time)
            for b, _ in latched:
                self.latched.remove((b, key))
                if (b, key) in self.dispatcher.orphans:
                    self.dispatcher.orphans.remove((b, key))
                more += engine.release_holder(_latched(b), e.time)
            out += self.take_over(engine, more)
            if latched:
                self.after(engine)  # the latch state: the engine's own latch now, no orphan
        return out

    def reset(self) -> None:
        """~reset released every orphan (and the engine its holders): nothing latched is carried."""
        self.latched = [c for c in self.latched if c in self.dispatcher.orphans]

    def check(self, engine: Engine, now: float) -> None:
        """At each tick: release carried behaviours the rebuilt engine did not take over in time."""
        if not self.carried:
            return
        active = set(engine.active_behaviours())
        keep = []
        for b, key, until, holder in self.carried:
            if b.index in active and engine.spec.behaviours[b.index - 1] is b:
                self.dispatcher.handle(engine, engine.release_holder(holder, now), "clock jump")
                continue  # the engine holds it again, under the same identity
            if now >= until or now < until - 3600.0:
                self.dispatcher.release(b, key, now)
                self.dispatcher.report_event(Event(now, "release", b.index), b, (), "deadline")  # pairs its start
                self.dispatcher.handle(engine, engine.release_holder(holder, now), "clock jump")
            else:
                keep.append((b, key, until, holder))
        self.carried = keep


def _carried(b: Any) -> str:
    return f"{b.label} (carried across a clock jump)"


def _latched(b: Any) -> str:
    return f"{b.label} (latched before a clock jump)"


class ClockStall:
    """With use_sim_time, the /clock stopping (a paused simulator, a bag at its end, a dead
    simulator) stops ROS time: no `for` or `age` can advance, and no tick or ~heartbeat comes
    (the watchdog acts). Said once (then at most every LOG_EVERY s) after AFTER s of wall time
    without ROS time moving, and again when it moves. `check` is cheap: the watcher's thread
    calls it a few times a second, and the status asks `stalled` (computed live, so the first
    look after the clock moves again sees it moving)."""

    AFTER = 2.0  # s of wall time without ROS time moving
    LOG_EVERY = 10.0

    def __init__(self, now: Callable[[], float], wall: Callable[[], float], log: Log) -> None:
        self.now, self.wall, self.log = now, wall, log
        self._ros = now()
        self._since = wall()  # wall time ROS time last moved
        self._said = False  # this stall was logged: its end will be too
        self._logged = float("-inf")
        self._lock = threading.Lock()  # the watcher's thread and the status path both look

    def _observe(self) -> Tuple[float, float]:
        """(ROS time, wall seconds it has stood still); whoever first sees it move again says so."""
        with self._lock:
            ros, wall = self.now(), self.wall()
            if ros == self._ros:
                return ros, wall - self._since
            if self._said:
                self._said = False
                self.log("info", f"/clock moves again (ROS time {ros:.3f} s) after {wall - self._since:.1f} s "
                                 f"standing still")
            self._ros, self._since = ros, wall
            return ros, 0.0

    def stalled(self) -> str:
        """'' while ROS time moves; otherwise what to say (for /diagnostics)."""
        ros, still = self._observe()
        if still < self.AFTER:
            return ""
        return (f"no /clock for {still:.1f} s (use_sim_time): ROS time stands still at {ros:.3f} s, "
                f"`for` and `age` cannot advance and no ~heartbeat is published until it moves")

    def check(self) -> None:
        text = self.stalled()
        if not text:
            return
        with self._lock:
            if self._said or self.wall() - self._logged < self.LOG_EVERY:
                return
            self._said = True  # this stall is logged (and its end will be)
            self._logged = self.wall()
        self.log("warn", text)
