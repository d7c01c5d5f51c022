"""Live reload of the monitor (SIGHUP, ~reload): re-read the spec and its libraries, check
them, and swap them in on the engine's thread, or keep the running rules on any error. Active
actions and latches are carried across by name (docs/failure-modes.md)."""
from __future__ import annotations

import os
import queue
import threading
import time
from contextlib import contextmanager
from typing import Any, Dict, Iterator, List, Optional, Tuple

import rospy

from ..actions.runner import ActionRunner
from ..engine import Engine, Event
from ..lang import SpecError, load_spec
from ..lang.errors import RubassError, counted
from ..lang.libtopics import running_type_changes
from ..lang.model import CheckedSpec
from .clockjump import horizon
from .gcfreeze import freeze_heap
from .livecheck import live_errors
from .topics import ros_now


class StartupError(RubassError):
    """The spec, a library or an action cannot be used: the message says why, for the user."""


class ConfigError(StartupError):
    """The parameters do not fit the spec (~overload_actions): the monitor exits."""


@contextmanager
def said_if_slow(text: str, after: float = 1.0) -> Iterator[None]:
    """Log `text` (WARN) if the block takes over `after` seconds: setting up actions registers their
    publishers with the master, which rospy waits for without a word, and a wait that says nothing
    looks like one that took effect."""
    slow = threading.Timer(after, lambda: rospy.logwarn(text))
    slow.daemon = True
    slow.start()
    try:
        yield
    finally:
        slow.cancel()


class Reloading:
    """The reload half of the Monitor (mixed into it): reads `config`, `spec`, `runners`, `loop`,
    `dispatcher`, `keeper`, `watcher`, `sampler` and the checks the Monitor defines."""

    config: Any
    spec: Optional[CheckedSpec]
    runners: Dict[str, ActionRunner]
    loop: Any
    dispatcher: Any
    keeper: Any
    watcher: Any
    sampler: Any
    reloads: int
    rejected: int
    coalesced: int
    last_reload_error: str
    load_error: str
    _reload_lock: threading.RLock
    _reload_wanted: threading.Event
    _starting: bool
    _start_lock: threading.Lock
    _reload_deferred: List[str]
    _exit: threading.Event
    _reload_reason: str = "SIGHUP"  # what asked for the reload the reload thread runs next

    def request_reload(self, reason: str = "SIGHUP") -> None:
        """From the SIGHUP handler: wake the reload thread. A request that arrives while another
        waits behind the running reload is coalesced into it: that one reads the newest files
        anyway, so a storm of SIGHUPs costs at most two reloads. `reason`: what the log says asked."""
        self._reload_reason = reason
        if self._reload_wanted.is_set():
            self.coalesced += 1
        self._reload_wanted.set()

    def reload_thread(self) -> None:
        """The one thread that runs every SIGHUP reload, for the monitor's lifetime: a storm of
        SIGHUPs starts no threads. Whatever a reload raises, it lives on for the next one."""
        while True:
            self._reload_wanted.wait()
            self._reload_wanted.clear()
            reason, self._reload_reason = self._reload_reason, "SIGHUP"
            try:
                self.reload(reason)
            except queue.Empty:
                rospy.logerr("rubass: reload (%s): the engine's thread did not take the new rules within "
                             "its timeout (stalled?); the swap may still happen when it answers", reason)
            except Exception as exc:  # noqa: BLE001 - the next SIGHUP must still be served
                rospy.logerr("rubass: reload (%s) failed: %s: %s", reason, exc.__class__.__name__, exc)

    def reload(self, reason: str) -> Tuple[bool, str]:
        """Re-read spec and libraries; swap atomically, or keep the old rules on any error."""
        with self._start_lock:
            if self._starting:  # the spec may be read, enforcement not begun: once it is, read again (setup)
                if reason not in self._reload_deferred:
                    self._reload_deferred.append(reason)
                rospy.loginfo("rubass: reload (%s) asked while the monitor starts: it reads the spec again as "
                              "soon as it enforces", reason)
                return False, ("the monitor is still starting (reading its spec, or waiting for the first "
                               "/clock): it reads the spec again as soon as it enforces")
        if self._exit.is_set():
            return False, "the monitor is stopping"
        with self._reload_lock:
            t0 = time.monotonic()
            try:
                spec = self._load_stable()
                self._check_overload_actions(spec)
                self._check_actions(spec)
                self._check_running_types(spec)
                self._check_live_types(spec)
                t_check = time.monotonic()
                if self.spec is not None and self.loop is None:  # stopped before it enforced
                    raise StartupError(f"not enforcing: {self._why_not()}")
                if self.spec is None:  # not enforcing yet: this spec is the first usable one
                    self._enforce(spec, self._runners(spec, {}))
                    self.reloads += 1
                    self.last_reload_error = ""
                    freeze_heap()
                    return True, (f"enforcing {spec.path}: {counted(len(spec.rules), 'rule')}, "
                                  f"{counted(len(spec.behaviours), 'behaviour')}")
                if spec.behaviours == [] and self.spec.behaviours:
                    raise StartupError(f"{spec.path}: the new spec has no behaviours; refusing to drop every "
                                       f"safety behaviour of the running spec (was the file caught half-written? "
                                       f"to run without rules, restart the monitor)")
                gone = [n for n, r in self.runners.items()
                        if n not in spec.actions and r.active and self.spec.actions[n].latch]
                if gone:  # actions are carried by name: a latched one that is on cannot just vanish
                    raise StartupError(f"{spec.path}: the new spec no longer declares {', '.join(gone)}, which is "
                                       f"latched and active, and no action library it loads defines it any more "
                                       f"(renamed or removed); call ~reset first (or keep the action's name)")
                unlatched = [n for n, r in self.runners.items() if n in spec.actions and r.active
                             and self.spec.actions[n].latch and not spec.actions[n].latch]
                if unlatched:  # it would release a protective stop without ~reset (a restart keeps holding it)
                    raise StartupError(f"{spec.path}: the new action library makes {', '.join(unlatched)} not latched "
                                       f"(latch: false) while it is latched and active: the reload would release "
                                       f"the stop without ~reset; call ~reset first (once its cause is gone), then "
                                       f"reload")
                with said_if_slow(f"rubass: reload ({reason}): setting up its new actions waits for the master (a "
                                  f"new publisher or service registers with it); the previous rules keep running "
                                  f"until it answers"):
                    runners = self._runners(spec, self.runners)
            except (SpecError, StartupError) as exc:
                text = self._failed_text(exc) if isinstance(exc, SpecError) else str(exc)
                self.rejected += 1
                self.last_reload_error = text.splitlines()[0] if text else "error"
                if self.spec is None:
                    self.load_error = text
                kept = "nothing is enforced yet" if self.loop is None else "the previous rules keep running"
                rospy.logerr("rubass: reload (%s) rejected, %s:\n%s", reason, kept, text)
                return False, f"rejected, {kept}: {text}"
            built = [r for n, r in runners.items() if self.runners.get(n) is not r]
            try:
                new_engine = Engine(spec, ros_now())
                t_build = time.monotonic()
                for runner in built:
                    runner.start_thread()
                self.loop.call(lambda old: self._swap(old, new_engine, spec, runners))  # type: ignore[union-attr]
            except queue.Empty:
                raise  # the swap may still happen on the engine's thread: keep what it will use
            except Exception as exc:  # a bug must not leave half a reload: the running rules stay whole
                for runner in built:
                    runner.stop(timeout=1.0)
                    runner.plugin.close()
                text = f"{exc.__class__.__name__}: {exc}"
                self.rejected += 1
                self.last_reload_error = text
                rospy.logerr("rubass: reload (%s) failed while swapping in the new rules, the previous rules keep "
                             "running: %s", reason, text)
                return False, f"rejected: {text}"
            t_swap = time.monotonic()
            self.watcher.sync(spec)
            if spec.nodes != self.spec.nodes:
                self.sampler.stop()
                self.sampler = self._sampler(spec, self.sampler)
            dropped = [r for n, r in self.runners.items() if runners.get(n) is not r]
            self.retired_failures += sum(r.stats.failures for r in dropped)  # the record is since start
            self.spec, self.runners = spec, runners
            for runner in dropped:
                runner.stop()
                runner.plugin.close()
            self.reloads += 1
            self.last_reload_error = ""
            freeze_heap()  # the new spec and engine leave the collector's scans, as at start (gcfreeze.py)
            ms = (time.monotonic() - t0) * 1000.0
            rospy.loginfo("rubass: reloaded %s (%s) in %.0f ms: %s, %s (check %.0f ms, build %.0f ms, "
                          "swap %.1f ms)", spec.path, reason, ms, counted(len(spec.rules), "rule"),
                          counted(len(spec.behaviours), "behaviour"),
                          (t_check - t0) * 1000, (t_build - t_check) * 1000, (t_swap - t_build) * 1000)
            return True, (f"reloaded in {ms:.0f} ms: {counted(len(spec.rules), 'rule')}, "
                          f"{counted(len(spec.behaviours), 'behaviour')}")

    def _check_running_types(self, spec: CheckedSpec) -> None:
        """A new action must not change the type of a topic the running actions publish: rospy keeps
        one publisher per topic in a node, and the running one is still registered while the new
        actions are built, so their messages would go out as the old type (garbage; the stop
        never reaches the base). Changing a topic's type needs a restart."""
        running = [r.plugin.action for r in self.runners.values()]
        new = sorted(spec.actions.values(), key=lambda a: (a.span.file, a.span.line, a.span.col, a.name))
        errors = running_type_changes(running, new, rospy.resolve_name)
        if errors:
            raise StartupError("\n".join(d.render(spec.sources) for d in errors))

    def _check_live_types(self, spec: CheckedSpec) -> None:
        """The new spec against the message types its topics carry now, as `rubass check --live`:
        a field the type lacks would read unknown from the swap on (an active stop released for a
        typo), and a unit or kind error is an error too; the running rules are kept instead."""
        watcher = getattr(self, "watcher", None)  # none before the first spec is enforced
        types = watcher.carried_types() if watcher is not None else {}
        errors = live_errors(spec, self.config.actions, types) if types else []
        livecheck = getattr(self, "livecheck", None)
        if livecheck is not None and types:
            livecheck.known(spec, types, errors)  # its thread need not check the new spec against these again
        if errors:  # the first line is the first error itself: it is what /diagnostics shows of a rejection
            raise StartupError("\n".join(errors) + "\n(the new spec does not fit the message types its topics "
                               "carry now, as `rubass check --live` reads them)")

    def _load_stable(self) -> CheckedSpec:
        """load_spec, again if a file changed while it was read or within the last 50 ms (an
        editor or a script still writing it): a half-written file must not become the rules."""
        paths = [self.config.spec] + list(self.config.actions)
        for _ in range(5):
            before = _stamps(paths)
            spec = load_spec(self.config.spec, self.config.actions)
            files = paths + [lib for lib in spec.libraries if lib not in paths]
            if _stamps(paths) == before and time.time() - _newest(_stamps(files)) > 0.05:
                return spec
            time.sleep(0.1)
        return load_spec(self.config.spec, self.config.actions)

    def _hold_lost_history(self, new: Engine, events: List[Event], now: float) -> List[Event]:
        """An active behaviour whose edit restarted its condition's `for`/`within` (operators added or
        moved) may read false only for want of that history: it is not released at the reload but held
        until its condition could hold again (the spec's longest window, plus 0.5 s, as across a clock
        jump); if it starts again by then it goes on with no second start (ClockJump.take_over)."""
        if not new.history_lost:
            return events
        held = dict(new.history_lost)
        until = now + horizon(new.spec)
        keys = self.dispatcher.keys_of(new.spec)
        out: List[Event] = []
        for e in events:
            if e.kind == "release" and e.behaviour in held:
                b = new.spec.behaviours[e.behaviour - 1]
                self.clock_jump.carry(b, keys[b.index], until, held.pop(e.behaviour))
                rospy.logwarn("rubass: %s: the reload restarted its condition's `for`/`within`; held until it could "
                              "hold again (%.1f s), then released unless it does", b.label, until - now)
                continue
            out.append(e)
        for holder in held.values():  # still active by itself: nothing to hold over
            out += new.release_holder(holder, now)
        return out

    def _swap(self, old: Engine, new: Engine, spec: CheckedSpec, runners: Dict[str, ActionRunner]) -> None:
        """On the engine's thread: nothing is evaluated between the old rules and the new."""
        now = ros_now()
        self._on_events(old.advance(now), "deadline")  # what fell due up to the swap, under the old rules
        events = self._hold_lost_history(new, new.adopt(old, now, carry=_held_over), now)
        old_keys = self.dispatcher.keys_of(old.spec)
        old_runners = self.dispatcher.runners
        leaving = {old_keys[o.checked.index] for o in new.orphans if not o.checked.latched}
        for name, runner in runners.items():  # actions are carried across any reload by name
            prev = old_runners.get(name)
            if prev is not None and prev is not runner:
                runner.adopt(prev, leaving)
        self.dispatcher.runners = runners
        self.loop.engine = new  # type: ignore[union-attr]
        for orphan in new.orphans:  # in ~events before the new rules' starts: one that reads as the old (a
            b = orphan.checked  # renamed entity's unnamed behaviour, the same number) pairs as still on
            if not b.latched:
                self.dispatcher.report_event(Event(now, "release", b.index), b, (), "reload")  # pairs its start
        self._on_events(events, "reload")  # the latch state is written before a latched start is dispatched
        # Then what the new rules no longer hold: after their starts, so that an action a new (renamed,
        # edited) behaviour holds too is never released in between (its board would read "R" then "S").
        gone = {**old_runners, **runners}  # an action no library defines any more: its old runner releases it
        for orphan in new.orphans:
            b = orphan.checked
            if b.latched:
                self.dispatcher.orphans.append((b, old_keys[b.index]))
            else:
                self.dispatcher.release(b, old_keys[b.index], now, gone)
        self.keeper.save(new, self.dispatcher.orphans, self._fail_safes())


def _held_over(b: Any) -> str:
    return f"{b.label} (held over a reload that restarted its condition's `for`/`within`)"


def _stamps(paths: List[str]) -> List[Tuple[int, int]]:
    """(mtime in ns, size) of each file; (0, -1) for one that cannot be read."""
    out = []
    for p in paths:
        try:
            st = os.stat(p)
            out.append((st.st_mtime_ns, st.st_size))
        except OSError:
            out.append((0, -1))
    return out


def _newest(stamps: List[Tuple[int, int]]) -> float:
    return max((m for m, _ in stamps), default=0) / 1e9
