"""One thread per action: phases run in order off the engine's thread, holds are coalesced,
and a failing start or release is retried until it succeeds or is superseded; a plugin call that
does not return is reported by a watchdog thread shared by every runner.

submit() never blocks: the engine thread hands over and goes on evaluating.
"""
from __future__ import annotations

import collections
import threading
import time
import weakref
from typing import AbstractSet, Any, Callable, Deque, Dict, Optional, Set, Tuple

from .base import ActionPlugin, ActionStats, Context, Skipped
from .status import NOTHING_DONE, RESOLVED

Log = Callable[[str, str], None]  # (level, text)
BACKOFF = (0.05, 0.1, 0.2, 0.5, 1.0)
MAX_PENDING = 1000  # phases waiting for a plugin that is slower than the condition flaps
LOG_EVERY = 5.0  # seconds between two log lines about the same failing action
STUCK_AFTER = 2.0  # a plugin call still running this long (beyond the plugin's own call_timeout) is stuck
WATCH_EVERY = 0.25  # how often the watchdog looks at the calls in progress
# the phases whose success resolves a failure of each phase; a plugin's bad input only by the plugin
# (a good input: holds succeed at 50 Hz whatever the input); the runner's own by the next phase
# what a failing start or release says once the opposite phase supersedes it: no longer retried, and
# still a failure (ERROR in /diagnostics) until an attempt of the action really succeeds
_GIVEN_UP = {"start": " (no longer retried: released before an attempt succeeded)",
             "release": " (no longer retried: started again before an attempt succeeded)"}
_RESOLVED_BY = {"start": ("start", "release"), "release": ("release", "start"),
                "hold": ("hold", "start", "release"), "periodic": ("periodic", "start", "release"), "input": ()}


class ActionRunner:
    def __init__(self, plugin: ActionPlugin, log: Log) -> None:
        self.plugin = plugin
        self.log = log
        self.stats = ActionStats()
        self._cond = threading.Condition()
        self._queue: Deque[Tuple[str, Context]] = collections.deque()
        self._hold_pending = False
        self._active: Set[Any] = set()  # identities of the behaviours this action is active for
        self._held: Dict[Any, Context] = {}  # each holder's start context (carried across a reload)
        self._stop = False
        self._next_periodic = float("inf")
        self._last_log = 0.0
        self._thread: Optional[threading.Thread] = None
        self._call_lock = threading.Lock()  # the call in progress, shared with the watchdog's thread
        self._call: Optional[Tuple[str, float]] = None  # (phase, monotonic start) of the plugin call running now
        self._stuck = False  # the call in progress has been reported stuck
        self._before_stuck = ("", "")  # stats.failing and last_error when it was: given back when it returns
        self._stuck_log = 0.0
        plugin.wake = self.wake  # type: ignore[method-assign]
        plugin.stats = self.stats  # a plugin may count failures of its own threads (limit: a bad input)

    @property
    def active(self) -> bool:
        return bool(self._active)

    @property
    def stuck_after(self) -> float:
        """Seconds a plugin call may run before it is reported stuck: STUCK_AFTER beyond the time the
        plugin itself may block (its `call_timeout`: a service's timeout, a serial write timeout)."""
        own = getattr(self.plugin, "call_timeout", 0.0)
        return STUCK_AFTER + (float(own) if isinstance(own, (int, float)) and own > 0 else 0.0)

    def start_thread(self) -> None:
        self._thread = threading.Thread(target=self._run, name=f"rubass-action-{self.plugin.name}", daemon=True)
        self._thread.start()
        _WATCHDOG.add(self)

    def stuck(self, now: float) -> Optional[str]:
        """Whether the plugin call in progress has run longer than `stuck_after` at `now` (monotonic);
        if so it is counted once, logged (again every LOG_EVERY s) and makes the action failing until
        it returns. Called from another thread than the (stuck) runner's: the watchdog's."""
        with self._call_lock:
            if self._call is None:
                return None
            what, since = self._call
            if now - since < self.stuck_after:
                return None
            text = f"{what} has not returned for {now - since:.1f} s: the action is stuck"
            first, self._stuck = not self._stuck, True
            if first:
                self.stats.failures += 1
                self._before_stuck = (self.stats.failing, self.stats.last_error)
            self.stats.failing = what
            self.stats.last_error = text
            say = first or now - self._stuck_log >= LOG_EVERY
            if say:
                self._stuck_log = now
        if say:
            self.log("error", f"action '{self.plugin.name}' {text}")
        return text

    # -- the engine's thread -------------------------------------------------------------
    def submit(self, kind: str, ctx: Context) -> None:
        per = self.plugin.per_behaviour
        with self._cond:
            if kind == "start":
                if ctx.ident in self._active:
                    return
                first = not self._active
                self._active.add(ctx.ident)
                self._held[ctx.ident] = ctx
                self.plugin.active = True
                if per or first:
                    self._queue.append((kind, ctx))
            elif kind == "release":
                if ctx.ident not in self._active:
                    return
                self._active.discard(ctx.ident)
                self._held.pop(ctx.ident, None)
                if not self._active:
                    self.plugin.active = False
                if per or not self._active:
                    self._queue.append((kind, ctx))
            else:
                if self._hold_pending or not self._active:
                    return
                self._hold_pending = True
                self._queue.append((kind, ctx))
            if len(self._queue) > MAX_PENDING:
                self._compact()
            self._cond.notify()

    def claim(self) -> None:
        """Before a start is submitted (the dispatcher claims every start of an instant first, so a
        higher-priority action that starts with a lower one owns the topic before either publishes)."""
        try:
            self.plugin.claim()
        except Exception as exc:  # noqa: BLE001 - a plugin's failure must never reach the engine
            self.log("error", f"action '{self.plugin.name}' claim failed: {exc.__class__.__name__}: {exc}")

    def adopt(self, old: "ActionRunner", leaving: AbstractSet[Any] = frozenset()) -> None:
        """Take over what the runner this one replaces (same action name, a reload changed its
        definition) holds: its holders stay holders and the action starts at once here, so a
        latched 20 Hz stop goes on across the reload (issue 13). `leaving`: the keys of behaviours the
        reload releases next (a per-behaviour plugin, a log, logs no start of theirs)."""
        with old._cond:
            held = dict(old._held)
        if not held:
            return
        starts = False
        with self._cond:
            first = not self._active
            for ident, ctx in held.items():
                if ident not in self._active:
                    self._active.add(ident)
                    self._held[ident] = ctx
                    if (ident[0] not in leaving) if self.plugin.per_behaviour else first:
                        self._queue.append(("start", ctx))
                        starts, first = True, False
            self.plugin.active = True
        if starts:  # its topic now, before the old runner leaves it: a lower action must not get it in between
            self.claim()
        with self._cond:
            self._cond.notify()

    def _compact(self) -> None:
        """Bound the queue: drop the oldest start that its own release follows (the pair is moot)."""
        items = list(self._queue)
        for i, (kind, ctx) in enumerate(items):
            if kind == "start":
                j = next((j for j in range(i + 1, len(items))
                          if items[j][0] == "release" and items[j][1].ident == ctx.ident), None)
                if j is not None:
                    del items[j]
                    del items[i]
                    self.stats.extra["dropped pairs"] = self.stats.extra.get("dropped pairs", 0) + 1
                    break
        else:
            items.pop(0)
        self._queue = collections.deque(items)
        if not self._active and not any(kind == "release" for kind, _ in items):
            self.plugin.unclaim()  # the start it claimed for never runs, nor does a release

    def wake(self) -> None:
        """Run the plugin's periodic work now, and its period from now on (any thread)."""
        with self._cond:
            self._next_periodic = time.monotonic()
            self._cond.notify()

    def stop(self, timeout: float = 2.0) -> None:
        _WATCHDOG.discard(self)
        with self._cond:
            self._stop = True
            self._cond.notify()
        if self._thread is not None:
            self._thread.join(timeout)

    # -- the runner's thread -------------------------------------------------------------
    def _run(self) -> None:
        while True:
            try:
                self._loop()
                return
            except Exception as exc:  # a bug in the runner itself must not end the action silently
                self.stats.failures += 1
                self.stats.failing = "runner"
                self.stats.last_error = f"runner: {exc.__class__.__name__}: {exc}"
                self.log("error", f"action '{self.plugin.name}': its runner failed ({exc.__class__.__name__}: "
                                  f"{exc}); going on")
                time.sleep(0.05)

    def _loop(self) -> None:
        if self.plugin.period:
            self._next_periodic = time.monotonic() + self.plugin.period
        while True:
            with self._cond:
                while not self._queue and not self._stop:
                    wait = self._next_periodic - time.monotonic()
                    if wait <= 0:
                        break
                    self._cond.wait(min(wait, 1.0))
                if self._stop and not self._queue:
                    return
                item = self._queue.popleft() if self._queue else None
                if item is not None and item[0] == "hold":
                    self._hold_pending = False
            if item is not None:
                self._do(*item)
            self._periodic_if_due()

    def _periodic_if_due(self) -> None:
        period = self.plugin.period
        if period and time.monotonic() >= self._next_periodic:
            self._guard("periodic", self.plugin.periodic)
            self._next_periodic = max(self._next_periodic + period, time.monotonic())

    def _superseded(self, kind: str, ctx: Context) -> bool:
        with self._cond:
            if self._stop:
                return kind != "release"
            mine = ctx.ident in self._active if self.plugin.per_behaviour else bool(self._active)
            return (kind == "start" and not mine) or (kind == "release" and mine)

    def _do(self, kind: str, ctx: Context) -> None:
        call = {"start": self.plugin.start, "hold": self.plugin.hold, "release": self.plugin.release}[kind]
        attempt = 0
        while attempt == 0 or not self._superseded(kind, ctx):  # retries only, never the first try
            if self._guard(kind, lambda: call(ctx)) or kind == "hold":
                return
            retry_at = time.monotonic() + BACKOFF[min(attempt, len(BACKOFF) - 1)]
            attempt += 1
            while True:  # the periodic work goes on meanwhile (a publish keeps its rate, a port reopens)
                with self._cond:
                    if self._stop and kind != "release":
                        return
                    now = time.monotonic()
                    # only a phase that supersedes this one cuts the wait: a hold queued behind a
                    # failing start must not turn the backoff into a spin (100 % of a core)
                    if now >= retry_at or (self._queue and self._superseded(kind, ctx)):
                        break
                    self._cond.wait(min(retry_at, self._next_periodic) - now)
                self._periodic_if_due()
            if self._stop and attempt > 3:
                return  # at shutdown a release is tried a few times, not forever
        if self.stats.failing == kind and kind in _GIVEN_UP:  # superseded while failing: still shown, as it is
            self.stats.last_error += _GIVEN_UP[kind]

    def _guard(self, what: str, fn: Callable[[], Any]) -> bool:
        with self._call_lock:
            self._call = (what, time.monotonic())
        try:
            result: Any = fn()
        except Skipped:
            self._returned()
            return False
        except Exception as exc:  # a plugin's failure must never reach the engine
            self._returned()
            with self._call_lock:  # the watchdog counts too
                self.stats.failures += 1
            self.stats.failing = what
            self.stats.last_error = f"{what}: {exc.__class__.__name__}: {exc}"
            now = time.monotonic()
            if now - self._last_log >= LOG_EVERY:
                self._last_log = now
                self.log("error", f"action '{self.plugin.name}' {what} failed ({self.stats.failures} failures so "
                                  f"far; retrying): {exc.__class__.__name__}: {exc}")
            return False
        except BaseException:  # SystemExit from a plugin: not a call still in progress
            self._returned()
            raise
        self._returned()
        if result is NOTHING_DONE:  # nothing was tried, so nothing is proved: no call, resolves nothing
            return True
        if what != "periodic":
            self.stats.calls += 1
        self._resolve(what)
        return True

    def _returned(self) -> None:
        """The plugin call returned: the watchdog no longer looks at it. A call it reported stuck
        gives the action back the failing state it had before (none, or another failure such as a
        limit's bad input), with the stuck call kept on record; then the call's own outcome counts."""
        with self._call_lock:
            call, stuck, self._call, self._stuck = self._call, self._stuck, None, False
            if not stuck:
                return
            text, (failing, error) = self.stats.last_error, self._before_stuck
            self.stats.failing = failing
            self.stats.last_error = error if failing else RESOLVED + text
        self.log("info", f"action '{self.plugin.name}' {call[0] if call else 'a call'} returned (it was stuck)")

    def _resolve(self, what: str) -> None:
        """A success after a failure: the error stays on record but no longer makes /diagnostics ERROR.
        Only a success that answers the failure resolves it: the same phase again, or the phase that
        made it moot (a release after a failed start); a hold that wrote nothing says nothing of a
        device that periodic() found away, nor a periodic() of a failed start."""
        failed, error = self.stats.failing, self.stats.last_error
        if not failed or what not in _RESOLVED_BY.get(failed, ("start", "hold", "release")):
            return
        self.stats.failing = ""
        self.stats.last_error = RESOLVED + error
        self.log("info", f"action '{self.plugin.name}' {what} succeeded after failing ({error})")


class _Watchdog:
    """One thread for every runner: it reads the call each runner has in progress, so a plugin call
    that never returns is reported without any help from the thread it holds."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._runners: "weakref.WeakSet[ActionRunner]" = weakref.WeakSet()
        self._thread: Optional[threading.Thread] = None

    def add(self, runner: ActionRunner) -> None:
        with self._lock:
            self._runners.add(runner)
            if self._thread is None or not self._thread.is_alive():
                self._thread = threading.Thread(target=self._run, name="rubass-action-watchdog", daemon=True)
                self._thread.start()

    def discard(self, runner: ActionRunner) -> None:
        with self._lock:
            self._runners.discard(runner)

    def _run(self) -> None:
        while True:
            time.sleep(WATCH_EVERY)
            with self._lock:
                runners = list(self._runners)
            for runner in runners:
                try:
                    runner.stuck(time.monotonic())
                except Exception:  # noqa: BLE001 - a log callback that fails must not end the watch
                    pass


_WATCHDOG = _Watchdog()
