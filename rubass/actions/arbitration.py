"""Arbitration by priority (LANGUAGE.md §16): of the active actions that publish on one topic,
only the one with the highest priority publishes; when it is released, the next active one is
told at once, so that the topic is handed over without a gap and without a stale message.

Pure: no ROS, no clock. Plugins call it from their runner threads; one lock per topic makes the
question "do I own the topic?" and the publication one step, so a released owner can never
publish after its successor has started.
"""
from __future__ import annotations

import itertools
import threading
from contextlib import contextmanager
from typing import Callable, Dict, Iterator, List, Optional

Handover = Callable[[], None]


class Seat:
    """One action's place on one topic."""

    def __init__(self, arbiter: "Arbiter", topic: str, name: str, priority: int, order: int,
                 on_handover: Handover) -> None:
        self.arbiter, self.topic, self.name, self.priority = arbiter, topic, name, priority
        self.order = order  # join order: breaks ties (only while a reload swaps an action for its new version)
        self.on_handover = on_handover
        self.active = False

    def activate(self) -> None:
        """The action started: it owns the topic if nothing active outranks it."""
        self.arbiter._set(self, True)

    def claim(self) -> None:
        """The action is about to start (called on the dispatching thread for every start of an
        instant before any runner is woken): it outranks lower actions at once, so none of them
        publishes first. Without the topic's lock, which a runner holds while its publication
        blocks (a stuck subscriber) and the engine's thread must never wait for; start() then
        activates it again under the lock."""
        self.active = True

    def unclaim(self) -> None:
        """A claimed start was dropped before it ran (its release came in the same queue)."""
        self.active = False

    def deactivate(self) -> None:
        """The action was released: if it owned the topic, the next active action takes it."""
        self.arbiter._set(self, False)

    def leave(self) -> None:
        """The action is closed (shutdown, or a reload dropped it)."""
        self.arbiter._leave(self)

    @property
    def owner(self) -> bool:
        return self.arbiter.owner(self.topic) is self

    @contextmanager
    def turn(self) -> Iterator[bool]:
        """`with seat.turn() as mine: if mine: publish(...)`: ownership cannot change meanwhile."""
        with self.arbiter._lock_of(self.topic):
            yield self.arbiter.owner(self.topic) is self


class Arbiter:
    """Which action publishes on each topic."""

    def __init__(self) -> None:
        self._guard = threading.Lock()
        self._locks: Dict[str, threading.RLock] = {}
        self._seats: Dict[str, List[Seat]] = {}
        self._order = itertools.count()

    def seat(self, topic: str, name: str, priority: int, on_handover: Handover = lambda: None) -> Seat:
        """A new, inactive seat for action `name` on `topic`."""
        s = Seat(self, topic, name, priority, next(self._order), on_handover)
        with self._lock_of(topic):
            self._seats.setdefault(topic, []).append(s)
        return s

    def owner(self, topic: str) -> Optional[Seat]:
        """The active seat with the highest priority (the earliest joined among equals), if any."""
        with self._lock_of(topic):
            active = [s for s in self._seats.get(topic, []) if s.active]
            return max(active, key=lambda s: (s.priority, -s.order)) if active else None

    def describe(self, topic: str) -> str:
        """'stop (waiting: crawl)', for status reports; '' when no action is active on it."""
        with self._lock_of(topic):
            owner = self.owner(topic)
            waiting = [s.name for s in self._seats.get(topic, []) if s.active and s is not owner]
        if owner is None:
            return ""
        return owner.name + (f" (waiting: {', '.join(waiting)})" if waiting else "")

    def _lock_of(self, topic: str) -> "threading.RLock":
        with self._guard:
            lock = self._locks.get(topic)
            if lock is None:
                lock = self._locks[topic] = threading.RLock()
            return lock

    def _set(self, seat: Seat, active: bool) -> None:
        with self._lock_of(seat.topic):
            before = self.owner(seat.topic)
            seat.active = active
            after = self.owner(seat.topic)
        self._handed(before, after, seat)

    def _leave(self, seat: Seat) -> None:
        with self._lock_of(seat.topic):
            before = self.owner(seat.topic)
            seat.active = False
            seats = self._seats.get(seat.topic, [])
            if seat in seats:
                seats.remove(seat)
            after = self.owner(seat.topic)
        self._handed(before, after, seat)

    @staticmethod
    def _handed(before: Optional[Seat], after: Optional[Seat], changed: Seat) -> None:
        """Tell a seat that the topic came to it from another (outside the lock: the callback
        wakes a runner thread, which will take the lock to publish)."""
        if after is not None and after is not before and after is not changed:
            after.on_handover()
