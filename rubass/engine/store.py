"""What the engine knows about the world at one instant: field values, arrivals, node samples,
rule values, and the current time. Written only by the engine's thread."""
from __future__ import annotations

import bisect
from typing import Any, Dict, List, Optional, Tuple

from ..lang.ast import PathElem
from .values import UNKNOWN


class Store:
    def __init__(self, now: float, origin: float = 0.0) -> None:
        self.now = now
        self.origin = origin  # the absolute time of now = 0 (replay runs from 0; header stamps are absolute)
        self.fields: Dict[Tuple[str, Tuple[PathElem, ...]], Any] = {}
        self.rules: Dict[str, Any] = {}
        self.watch_start: Dict[str, float] = {}
        self.last_arrival: Dict[str, float] = {}
        self._arrivals: Dict[str, List[float]] = {}
        self._window: Dict[str, float] = {}
        self.nodes: Dict[str, Dict[str, Any]] = {}
        self.stamps: Dict[str, Any] = {}  # topic -> header.stamp of its last message, seconds
        self.rates: Dict[Tuple[str, Tuple[PathElem, ...]], Any] = {}
        self._rate_last: Dict[Tuple[str, Tuple[PathElem, ...]], Tuple[float, Any]] = {}
        self.laser_limits: Dict[str, Optional[Tuple[float, float]]] = {}
        # field slot -> [its value], the same as in `fields`: what compiled expressions read (a
        # key with a slice in its path costs a Python-level hash at every dict lookup)
        self._cells: Dict[Tuple[str, Tuple[PathElem, ...]], List[Any]] = {}

    def cell(self, slot: Tuple[str, Tuple[PathElem, ...]]) -> List[Any]:
        """The one-element list that always holds the slot's value (UNKNOWN until one is stored)."""
        c = self._cells.get(slot)
        if c is None:
            c = self._cells[slot] = [self.fields.get(slot, UNKNOWN)]
        return c

    def sync_cells(self) -> None:
        """After `fields` was written directly (a live reload carrying values over)."""
        for slot, c in self._cells.items():
            c[0] = self.fields.get(slot, UNKNOWN)

    def watch(self, topic: str, now: float, window: float = 0.0) -> None:
        """Start watching a topic (age counts from here); keep arrivals for `window` seconds."""
        self.watch_start.setdefault(topic, now)
        self._window[topic] = max(self._window.get(topic, 0.0), window)
        self._arrivals.setdefault(topic, [])

    def arrive(self, topic: str, now: float) -> None:
        self.last_arrival[topic] = now
        window = self._window.get(topic, 0.0)
        if window > 0.0:
            arr = self._arrivals[topic]
            arr.append(now)
            if len(arr) > 64 and arr[len(arr) // 2] < now - window:  # drop the old half at once
                del arr[: bisect.bisect_left(arr, now - window)]

    def carry_topic(self, other: "Store", topic: str) -> None:
        """Keep what another store knew of a topic: watch start, arrivals, stamps, rates (live reload)."""
        self.watch_start[topic] = other.watch_start[topic]
        if topic in other.last_arrival:
            self.last_arrival[topic] = other.last_arrival[topic]
        self._arrivals[topic] = list(other._arrivals.get(topic, []))
        if topic in other.stamps:
            self.stamps[topic] = other.stamps[topic]
        if topic in other.laser_limits:
            self.laser_limits[topic] = other.laser_limits[topic]
        for key in other._rate_last:
            if key[0] == topic:
                self._rate_last[key] = other._rate_last[key]
                self.rates[key] = other.rates.get(key, UNKNOWN)

    def arrive_rate(self, topic: str, path: Tuple[PathElem, ...], now: float, value: Any) -> None:
        """rate(topic /t.f) (§11): the change of f per second over its last two messages."""
        key = (topic, path)
        last = self._rate_last.get(key)
        self._rate_last[key] = (now, value)
        rate: Any = UNKNOWN
        if last is not None and type(value) is float and type(last[1]) is float and now != last[0]:
            rate = (value - last[1]) / (now - last[0])
            if rate != rate:
                rate = UNKNOWN
        self.rates[key] = rate

    def stamp_age(self, topic: str) -> Any:
        """now − header.stamp of the last message (§11); unknown before one, or for a zero stamp."""
        stamp = self.stamps.get(topic, UNKNOWN)
        return UNKNOWN if stamp is UNKNOWN else self.now + self.origin - stamp

    def age(self, topic: str) -> Any:
        last = self.last_arrival.get(topic, self.watch_start.get(topic))
        return UNKNOWN if last is None else max(0.0, self.now - last)

    def frequency(self, topic: str, window: float) -> Any:
        start = self.watch_start.get(topic)
        if start is None or self.now - start < window:
            return UNKNOWN
        arr = self._arrivals.get(topic, [])
        lo = bisect.bisect_right(arr, self.now - window)
        hi = bisect.bisect_right(arr, self.now)
        return (hi - lo) / window

    def next_frequency_change(self, topic: str, window: float) -> Optional[float]:
        """The next instant frequency(topic, window) changes without a new message."""
        start = self.watch_start.get(topic)
        if start is None:
            return None
        if self.now - start < window:
            return start + window
        arr = self._arrivals.get(topic, [])
        lo = bisect.bisect_right(arr, self.now - window)
        return arr[lo] + window if lo < len(arr) else None

    def node_value(self, node: str, attr: str) -> Any:
        return self.nodes.get(node, {}).get(attr, UNKNOWN)
