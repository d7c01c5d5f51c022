"""The engine's thread: every input goes through one queue, and the thread wakes at each tick
and at the engine's next deadline, so a `for` fires at its instant, not at the next tick.

Only the standard library: the clock is injected (ROS time in the monitor, a monotonic clock
in benchmarks, a manual one in tests), and events are handed to a callback.
"""
from __future__ import annotations

import dataclasses
import math
import queue
import threading
import time
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Optional, Tuple

from .engine import Engine, Event

Handler = Callable[[List[Event], Any], None]  # (events, cause: the input item, or None for a wake-up)
JumpHook = Callable[[Engine, float], Tuple[Engine, List[Event]]]  # (old engine, now) -> new engine, its events


@dataclass(frozen=True)
class Message:
    topic: str
    time: float
    msg: Any = None
    received: float = 0.0  # wall-clock arrival, to measure reaction latency
    size: int = 0  # serialised bytes, counted against the queue's byte budget
    also: Tuple[str, ...] = ()  # the topic's other spellings in the spec: the same message, one instant
    arrived: float = 0.0  # monotonic arrival (s): how long it waited in the queue is measured from it (0: not)


@dataclass(frozen=True)
class NodeSample:
    node: str
    time: float
    alive: Any
    cpu: Any
    memory: Any


@dataclass(frozen=True)
class Call:
    """Run fn(engine) on the engine's thread (reset, reload, status) and return its result."""

    fn: Callable[[Engine], Any]
    done: "queue.Queue[Tuple[bool, Any]]"


class EngineLoop:
    """Owns an engine; `submit` from any thread, `run` on one.

    With `inline`, the thread that submits an input handles it at once when the engine is free
    (under the engine's lock, in queue order), rather than waking the engine's thread for each
    message: that thread then only wakes for deadlines and ticks, and for what queued up while
    another thread held the engine. Everything the engine does still happens under one lock, in
    the order inputs were queued. `on_error` gets what an input handled inline raised.

    How long a queued message waited before the engine took it (from its `arrived`, on `mono`)
    is kept for `take_waited`: a monitor whose engine cannot keep up drops nothing until the queue
    is full (100,000 messages: minutes at some rates), but its rules see the robot that late.
    """

    BURST = 256  # inputs one submitting thread handles before it leaves the rest to the engine's thread

    def __init__(self, engine: Engine, clock: Callable[[], float], rate: float, handler: Handler,
                 max_queue: int = 100000, tick_hook: Optional[Callable[[float], None]] = None,
                 max_bytes: int = 256 * 1024 * 1024, on_clock_jump: Optional[JumpHook] = None,
                 inline: bool = False, on_error: Optional[Callable[[Exception], None]] = None,
                 mono: Callable[[], float] = time.monotonic) -> None:
        self.engine = engine
        self.clock = clock
        self.period = 1.0 / rate
        self.handler = handler
        self.tick_hook = tick_hook
        self.inbox: "queue.Queue[Any]" = queue.Queue(maxsize=max_queue)
        self.dropped = 0
        self.dropped_by_topic: Dict[str, int] = {}  # what was dropped, for the overload fail-safe's log
        # Conflation: when the queue is full, the newest message of each topic waits here (it
        # replaces an older one of its topic), is handled at the engine's next step, and older
        # messages of its topic still queued are then skipped: the newest value is never lost.
        self._newest: Dict[str, Message] = {}
        self._applied: Dict[str, float] = {}  # topic -> time of the newest message handled out of turn
        self.max_bytes = max_bytes  # the queue holds at most this many message bytes (8 MB clouds…)
        self.queued_bytes = 0
        self._bytes_lock = threading.Lock()
        self._stop = threading.Event()
        self._next_tick = clock() + self.period
        # The clock jumping back (sim time reset, the wall clock stepped back) by more than this
        # restarts the engine's windows: its times belong to the old timeline (see on_clock_jump).
        self.on_clock_jump = on_clock_jump
        self.jump_tolerance = max(0.25, 2 * self.period)
        self._last_clock = clock()
        self.clock_jumps = 0
        self.inline = inline
        self.on_error = on_error
        self._engine_lock = threading.Lock()  # held while anything runs the engine (inline mode)
        self._wake = threading.Event()  # inline mode: an earlier deadline, or inputs left over
        self._sleep_until = math.inf  # when the engine's thread wakes next by itself
        self.mono = mono
        self._waited = [0.0, 0.0]  # the longest a message waited in the queue, per asker (take_waited)
        self._waited_lock = threading.Lock()  # the status thread takes its value while the engine notes one

    # -- any thread ----------------------------------------------------------------------
    def submit(self, item: Any) -> bool:
        """Queue an input; False if the queue is full, by count or by bytes: then a message is kept
        as its topic's newest (conflation) and the one it replaces, if any, is counted as dropped."""
        if self.inline and not self.inbox.queue and not self._newest and self._engine_lock.acquire(False):
            done = False
            try:
                if not self.inbox.queue and not self._newest:  # nothing waits before it: no queue
                    done = True
                    self._handle(item, queued=False)
                    self._wake_if_sooner()
            except Exception as exc:
                if self.on_error is None:
                    raise
                self.on_error(exc)
            finally:
                self._engine_lock.release()
            if done:
                if self.inbox.queue:
                    self._pump()  # queued by others meanwhile
                return True
        size = item.size if isinstance(item, Message) else 0
        if size:
            with self._bytes_lock:
                over = self.queued_bytes + size > self.max_bytes
                if over:
                    self._conflate(item)
                else:
                    self.queued_bytes += size
            if over:
                if self.inline:
                    self._pump()
                return False
        try:
            self.inbox.put_nowait(item)
        except queue.Full:
            self._unqueue(size)
            if isinstance(item, Message):
                with self._bytes_lock:
                    self._conflate(item)
            else:
                self.dropped += 1
            if self.inline:
                self._pump()  # what is queued, then the newest of each topic
            return False
        if self.inline:
            self._pump()
        return True

    def _pump(self) -> None:
        """Inline mode: handle what is queued, if no other thread is handling it already."""
        lock, pending = self._engine_lock, self.inbox.queue
        while pending and lock.acquire(False):
            handed = False
            try:
                handled = self._drain(self.BURST, self._next_tick)
                handed = handled >= self.BURST or bool(pending) and self.clock() >= self._next_tick
                if handed:
                    self._wake.set()  # the engine's thread goes on, after its tick
                else:
                    self._wake_if_sooner()
            except Exception as exc:
                if self.on_error is None:
                    raise
                self.on_error(exc)
            finally:
                lock.release()
            if handed:
                return
            # an input queued while we held the lock, whose thread could not take it, is ours

    def _wake_if_sooner(self) -> None:
        """Under the engine's lock: wake its thread if the engine's next deadline is now sooner."""
        deadline = self.engine.next_deadline()
        if deadline is not None and deadline < self._sleep_until:
            self._wake.set()

    def _conflate(self, item: "Message") -> None:
        """Under _bytes_lock: keep `item` as its topic's newest; the one it replaces is dropped."""
        self.dropped += 1  # one message of this topic will never be seen: the replaced one, or queued ones
        self.dropped_by_topic[item.topic] = self.dropped_by_topic.get(item.topic, 0) + 1
        self._newest[item.topic] = item

    def _unqueue(self, size: int) -> None:
        if size:
            with self._bytes_lock:
                self.queued_bytes -= size

    def call(self, fn: Callable[[Engine], Any], timeout: float = 5.0) -> Any:
        """Run fn on the engine's thread and wait for its result (its exception is re-raised)."""
        done: "queue.Queue[Tuple[bool, Any]]" = queue.Queue(maxsize=1)
        self.inbox.put(Call(fn, done), timeout=timeout)
        if self.inline:
            self._pump()
        ok, value = done.get(timeout=timeout)
        if not ok:
            raise value
        return value

    def take_waited(self, who: int = 0) -> float:
        """The longest a message waited in the queue before the engine took it (s), since `who` last
        asked (0: the tick's overload check, 1: the status)."""
        with self._waited_lock:
            waited, self._waited[who] = self._waited[who], 0.0
        return waited

    def _note_wait(self, arrived: float) -> None:
        waited = self.mono() - arrived
        with self._waited_lock:
            if waited > self._waited[0]:
                self._waited[0] = waited
            if waited > self._waited[1]:
                self._waited[1] = waited

    def stop(self) -> None:
        self._stop.set()
        self._wake.set()
        try:
            self.inbox.put_nowait(None)
        except queue.Full:
            pass

    # -- the engine's thread -------------------------------------------------------------
    def run(self) -> None:
        while not self._stop.is_set():
            self.step()

    def step(self, max_wait: Optional[float] = None) -> None:
        """Wait for an input or the next wake-up, then handle everything that is due."""
        if self.inline:
            with self._engine_lock:
                timeout = self._wait_for(max_wait)
                self._sleep_until = self._last_clock + timeout
            if timeout > 0 and not self.inbox.queue and not self._newest:
                self._wake.wait(timeout)
            self._wake.clear()
            with self._engine_lock:
                self._sleep_until = -math.inf  # awake: a submitting thread need not wake it
                self._drain(self.BURST, self._next_tick)
                self._due()
            return
        timeout = self._wait_for(max_wait)
        try:
            item = self.inbox.get(timeout=timeout) if timeout > 0 else self.inbox.get_nowait()
        except queue.Empty:
            item = None
        if item is not None:
            self._handle(item)
        if self._newest:
            self._handle_newest()
        elif self._applied and self.inbox.empty():
            self._applied.clear()  # every message queued before those has been handled
        self._due()

    def _wait_for(self, max_wait: Optional[float]) -> float:
        """How long to wait for an input before the next wake-up (a clock jump is handled here)."""
        now = self.clock()
        if now < self._last_clock - self.jump_tolerance:
            self._clock_jumped(now)
        self._last_clock = now
        if self._next_tick > now + 2 * self.period:  # the clock jumped back (sim time restarted, NTP)
            self._next_tick = now + self.period
        wake = self._next_tick
        deadline = self.engine.next_deadline()
        if deadline is not None and deadline < wake:
            wake = deadline
        timeout = max(0.0, wake - now)
        if max_wait is not None:
            timeout = min(timeout, max_wait)
        return timeout

    def _drain(self, limit: Optional[int], until: float = math.inf) -> int:
        """Handle up to `limit` queued inputs (all, if None) in queue order, then the conflated newest;
        from the second on, none once the clock reads `until` (the tick: a busy engine still ticks, so
        its overload check and the rules of time run between messages, not after a whole burst)."""
        get, handled, clock = self.inbox.get_nowait, 0, self.clock
        while limit is None or handled < limit:
            if handled and until <= clock():
                break
            try:
                item = get()
            except queue.Empty:
                break
            if item is not None:
                self._handle(item)
                handled += 1
        if self._newest:
            self._handle_newest()
        elif self._applied and not self.inbox.queue:
            self._applied.clear()  # every message queued before those has been handled
        return handled

    def _due(self) -> None:
        """The deadlines that are due, and the tick."""
        now = self.clock()
        deadline = self.engine.next_deadline()
        if deadline is not None and deadline <= now:
            self._emit(self.engine.advance(now), None)
        if now >= self._next_tick:
            self._emit(self.engine.on_tick(now), None)
            if self.tick_hook is not None:
                self.tick_hook(now)
            self._next_tick += self.period
            if self._next_tick <= now:  # ticks were missed (a stall): go on from now, no burst
                self._next_tick = now + self.period

    def _clock_jumped(self, now: float) -> None:
        """Time went back: a new engine at `now` (the hook carries what must stay active)."""
        self.clock_jumps += 1
        self._next_tick = now + self.period
        self._applied.clear()
        if self.on_clock_jump is not None:
            self.engine, events = self.on_clock_jump(self.engine, now)
        else:
            self.engine = Engine(self.engine.spec, now)
            events = self.engine.evaluate_all(now)
        self._emit(events, "clock")

    def _handle_newest(self) -> None:
        """The newest message of each topic that overflowed, in time order, before older queued ones."""
        with self._bytes_lock:
            items, self._newest = sorted(self._newest.values(), key=lambda m: m.time), {}
        for m in items:
            if m.arrived:
                self._note_wait(m.arrived)
            self._applied[m.topic] = m.time
            self._emit(self._on_message(m), m)

    def _handle(self, item: Any, queued: bool = True) -> None:
        if isinstance(item, (Message, NodeSample)) and item.time < self._last_clock - self.jump_tolerance:
            now = self.clock()  # behind the loop's clock: a late message, or the clock went back before
            if now < self._last_clock - self.jump_tolerance:  # the engine's thread saw it: the jump, now,
                self._clock_jumped(now)  # so that the old engine never reads a time of the new timeline
                self._last_clock = now
        if self.clock_jumps and isinstance(item, (Message, NodeSample)) and \
                item.time > self._last_clock + self.jump_tolerance:
            item = dataclasses.replace(item, time=self.clock())  # stamped on the old timeline, before the jump
        if isinstance(item, Message):
            if queued:
                self._unqueue(item.size)
                if item.arrived:
                    self._note_wait(item.arrived)
            if self._applied and item.time <= self._applied.get(item.topic, float("-inf")):
                return  # older than a newer message of its topic already handled (conflated)
            self._emit(self._on_message(item), item)
        elif isinstance(item, NodeSample):
            self._emit(self.engine.on_node_sample(item.node, item.time, item.alive, item.cpu, item.memory), item)
        elif isinstance(item, Call):
            try:
                item.done.put((True, item.fn(self.engine)))
            except Exception as exc:  # handed back to the caller's thread
                item.done.put((False, exc))

    def _on_message(self, m: Message) -> List[Event]:
        if m.also:  # every spelling of the topic at one instant: one evaluation after all of them
            return self.engine.on_messages(m.time, tuple((t, m.msg) for t in (m.topic,) + m.also))
        return self.engine.on_message(m.topic, m.time, m.msg)

    def _emit(self, events: List[Event], cause: Any) -> None:
        if events:
            self.handler(events, cause)
