"""Dynamic subscriptions: one rospy.AnyMsg subscriber per topic the spec names, whatever its
type. The type comes from each connection's header; messages are deserialised only for
topics whose fields the spec reads; field paths are checked when a topic's type is first
seen (and again when it changes; two types at once: topictypes.py). Subscriptions are made
in the background (see TopicWatcher), never under a lock the engine or a callback takes. Their
connections are read by the receiver's one thread (receiver.py), which calls `_on_frame` with
each message's bytes; rospy's threads call `_callback` where the receiver gives a connection back."""
from __future__ import annotations

import io
import queue
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, FrozenSet, List, Optional, Set, Tuple, Union

import genpy
import genpy.dynamic
import roslib.message
import rospy

from ..engine.values import UNKNOWN, UNREADABLE
from ..lang import ast
from ..lang.fielduse import field_needs
from ..lang.model import CheckedSpec
from . import topictypes
from .clockjump import ClockStall
from .msgtypes import check_path
from .receiver import Receiver
from .topictypes import RECHECK

_rostime = rospy.rostime


def ros_now() -> float:
    """rospy.get_rostime() in seconds; on the wall clock without building a rospy.Time each time."""
    if _rostime._rostime_current is None and _rostime._rostime_initialized:
        return time.time()
    return _rostime.get_rostime().to_sec()


def message_bytes(raw: Any) -> bytes:
    """A delivered message's serialised bytes. rospy gives every subscriber of a topic in one process
    the class of the first: the spec's `rospy.AnyMsg` (its bytes), or, on a topic rospy itself or
    another part of the monitor subscribed first with a type (`/clock` under use_sim_time, the
    agents' topic), that type's message, serialised again here."""
    buff = getattr(raw, "_buff", None)
    if buff is not None:
        return buff
    out = io.BytesIO()
    raw.serialize(out)
    return out.getvalue()


Submit = Callable[[str, float, Any, float, int], None]  # (spec topic, ROS time, message or None, wall, bytes)
SubmitAll = Callable[[Tuple[str, ...], float, Any, float, int], None]  # every spelling of the topic at once
Log = Callable[[str, str], None]


@dataclass
class TopicState:
    """What the monitor knows about one watched topic (for its status)."""

    spec_name: str
    resolved: str
    paths: Dict[Tuple[ast.PathElem, ...], List[str]]  # field path -> rules reading it
    aliases: Tuple[str, ...] = ()  # other spellings of this topic in the spec ('cmd_vel' beside '/cmd_vel')
    scalar: FrozenSet[Tuple[ast.PathElem, ...]] = frozenset()  # paths the spec uses as one value
    implicit: FrozenSet[Tuple[ast.PathElem, ...]] = frozenset()  # header.stamp only for stamp_age(): unknown if absent
    needs: Dict[Tuple[ast.PathElem, ...], str] = field(default_factory=dict)  # path -> 'number' | 'condition'
    messages: int = 0
    errors: List[str] = field(default_factory=list)
    subscriber: Optional[rospy.Subscriber] = None  # None until the registrar has made it
    # (md5, class, type) of the type evaluated, as one value: a callback of another publisher's
    # thread reads it in one step, never a class of one type beside the md5 of another
    decoder: Tuple[str, Any, str, bool] = ("", None, "", False)  # and whether no field the spec reads is in it
    gone: bool = False  # a reload dropped it (its subscription is dropped by the registrar)
    kinds: Dict[str, "topictypes.Kind"] = field(default_factory=dict)  # md5 -> a type seen now
    callers: Dict[str, Tuple[str, float]] = field(default_factory=dict)  # publisher -> (md5, newest message)
    mixed: Optional[str] = None  # while publishers of two types are on: what is wrong (a data error)
    mixed_logged: float = float("-inf")
    checked: float = 0.0  # wall time the types were last looked at

    @property
    def md5(self) -> str:
        return self.decoder[0]

    @property
    def cls(self) -> Any:
        """The class of the type evaluated; None when it cannot be loaded (or none came yet)."""
        return self.decoder[1]

    @property
    def type(self) -> str:
        return self.decoder[2]


class TopicWatcher:
    """Subscriptions are made and dropped by a thread of their own (the registrar): rospy
    retries a registration until the master answers, and holds its topic manager's lock
    meanwhile. `_lock` guards `topics` only for moments and never while rospy or the master is
    asked anything, so the engine's thread and the subscribers' callbacks never wait on the
    master: the rules of the topics already subscribed go on being enforced while a reload's
    new topic waits for the master (its values stay unknown until then)."""

    SLOW = 1.0  # s: a registration that takes longer is logged (the master does not answer)

    def __init__(self, submit: Submit, log: Log, submit_spellings: Optional[SubmitAll] = None,
                 receiver: Optional[Receiver] = None) -> None:
        self.submit = submit
        self.receiver = receiver  # one thread reads every watched topic (receiver.py); None: rospy's threads
        # every spelling of one message at one instant (one evaluation); without it, one submit each
        self.submit_spellings = submit_spellings
        self.log = log
        self.topics: Dict[str, TopicState] = {}  # by resolved name
        self._lock = threading.Lock()
        self._types_lock = threading.Lock()  # a topic's types (topictypes.py): no rospy call under it
        self._classes: Dict[str, Any] = {}  # md5 -> class
        # ("subscribe" | "unsubscribe", TopicState), a threading.Event to set once the jobs before it
        # are done, or None to end the registrar
        self._jobs: "queue.Queue[Union[Tuple[str, TopicState], threading.Event, None]]" = queue.Queue()
        self._registrar: Optional[threading.Thread] = None
        self._closed = False
        self.clock: Optional[ClockStall] = None  # with use_sim_time: says when /clock stops

    def sync(self, spec: CheckedSpec, wait: float = 1.0) -> None:
        """Subscribe to the spec's topics, unsubscribe from those it no longer names. Returns once
        the registrar has done so, or after `wait` seconds (the master does not answer): the
        subscriptions are then made when it does."""
        # relative, absolute and ~private names resolve once, by ROS rules, to one subscription:
        # every spelling of a topic in the spec gets the same messages (one value, not two topics)
        spellings: Dict[str, List[str]] = {}
        for t in sorted(spec.topics, key=lambda t: (not spec.topics[t].paths, t)):  # a reader of fields first
            spellings.setdefault(rospy.resolve_name(t), []).append(t)
        wanted = {r: names[0] for r, names in spellings.items()}
        scalar = scalar_paths(spec)
        needs = field_needs([r.expr for r in spec.rules] + [b.cond for b in spec.behaviours])
        readers, explicit = spec.field_readers(), spec.field_readers(implicit=False)
        users: Dict[str, Dict[Tuple[ast.PathElem, ...], List[str]]] = {}
        stamp_only: Dict[str, FrozenSet[Tuple[ast.PathElem, ...]]] = {}  # header.stamp read by stamp_age() only
        for names in spellings.values():
            merged: Dict[Tuple[ast.PathElem, ...], List[str]] = {}
            for n in names:
                for path, owners in readers[n].items():
                    merged.setdefault(path, []).extend(o for o in owners if o not in merged.get(path, []))
            users[names[0]] = merged
            stamp_only[names[0]] = frozenset(p for p in merged if not any(p in explicit[n] for n in names))
        jobs: List[Tuple[str, TopicState]] = []
        with self._lock:  # no rospy call under it: the registrar makes and drops subscriptions
            for resolved in [r for r in self.topics if r not in wanted]:
                state = self.topics.pop(resolved)
                state.gone = True
                jobs.append(("unsubscribe", state))
            for resolved, name in wanted.items():
                state = self.topics.get(resolved)
                aliases = tuple(spellings[resolved][1:])
                used_as_value = frozenset(p for n in spellings[resolved] for p in scalar.get(n, ()))
                needed = {p: k for n in reversed(spellings[resolved]) for p, k in needs.get(n, {}).items()}
                if state is None:
                    state = TopicState(name, resolved, users[name], aliases, used_as_value, stamp_only[name], needed)
                    self.topics[resolved] = state
                    jobs.append(("subscribe", state))
                else:
                    state.spec_name, state.paths, state.aliases = name, users[name], aliases
                    state.scalar, state.implicit, state.needs = used_as_value, stamp_only[name], needed
                    with self._types_lock:
                        for kind in state.kinds.values():
                            kind.problems = self._check(state, kind.cls, kind.type)
                            kind.unreadable = self._unreadable(state, kind)
                        if state.cls is not None:
                            state.errors = self._check(state, state.cls, state.type)
                        current = state.kinds.get(state.md5)
                        if current is not None:  # the new spec may read other fields of it
                            state.decoder = state.decoder[:3] + (current.unreadable,)
        if self.clock is None and not _rostime.is_wallclock() and _rostime._rostime_initialized:
            self.clock = ClockStall(ros_now, time.time, self.log)
            threading.Thread(target=self._watch_clock, name="rubass-clock", daemon=True).start()
        if not jobs:
            return
        done = threading.Event()
        for job in jobs:
            self._jobs.put(job)
        self._jobs.put(done)
        self._start_registrar()
        done.wait(wait)

    def _start_registrar(self) -> None:
        if self._registrar is None:
            self._registrar = threading.Thread(target=self._register_loop, name="rubass-subscribe", daemon=True)
            self._registrar.start()

    def _register_loop(self) -> None:
        """The registrar: every call that asks the master, one after the other."""
        while True:
            job = self._jobs.get()
            if job is None:
                return
            if isinstance(job, threading.Event):
                job.set()  # the jobs queued before it are done
                continue
            kind, state = job
            try:
                if kind == "subscribe":
                    self._subscribe(state)
                elif state.subscriber is not None:
                    sub, state.subscriber = state.subscriber, None
                    sub.unregister()
                    self._unroute(state)
            except Exception as exc:  # noqa: BLE001 - the registrar serves every later job
                self.log("error", f"topic {state.resolved}: cannot {kind}: {exc.__class__.__name__}: {exc}")

    def _watch_clock(self) -> None:
        while not self._closed:
            try:
                self.clock.check()  # type: ignore[union-attr]
            except Exception as exc:  # noqa: BLE001 - a log line lost, never the watch
                self.log("debug", f"clock watch: {exc.__class__.__name__}: {exc}")
            time.sleep(0.25)

    def _subscribe(self, state: TopicState) -> None:
        if state.gone or self._closed:
            return
        slow = threading.Timer(self.SLOW, lambda: self.log(
            "warn", f"topic {state.resolved}: the master does not answer: its subscription is made when it does, "
                    f"and the rules reading it stay unknown until then; every other rule is enforced meanwhile"))
        slow.daemon = True
        t0 = time.monotonic()
        slow.start()
        if self.receiver is not None:
            self.receiver.route(state.resolved, self._callback, self._on_frame, state)
        try:
            sub = rospy.Subscriber(state.resolved, rospy.AnyMsg, self._callback, callback_args=state,
                                   tcp_nodelay=True)
        finally:
            slow.cancel()
        took = time.monotonic() - t0
        with self._lock:
            keep = not state.gone and not self._closed
            if keep:
                state.subscriber = sub
        if not keep:  # dropped by a reload (or closed) while it waited for the master
            sub.unregister()
            self._unroute(state)
        elif took > self.SLOW:
            self.log("info", f"topic {state.resolved}: subscribed after {took:.1f} s (the master answers again)")

    def receiving(self, chosen: str) -> str:
        """Who reads the watched topics' connections, for /diagnostics (`chosen`: ~receiver)."""
        if self.receiver is not None:
            return self.receiver.describe()
        if chosen == "rospy":
            return "rospy's threads (~receiver: rospy)"
        return "rospy's threads (this rospy connects subscribers differently, see the log)"

    def _unroute(self, state: TopicState) -> None:
        if self.receiver is not None:
            self.receiver.unroute(state.resolved, state)

    def close(self, wait: float = 1.0) -> None:
        """Drop every subscription (by the registrar: a master that does not answer cannot hold
        the caller for more than `wait` seconds)."""
        with self._lock:
            self._closed = True
            states = list(self.topics.values())
            self.topics.clear()
            for state in states:
                state.gone = True
        for state in states:
            self._jobs.put(("unsubscribe", state))
        self._jobs.put(None)
        if self._registrar is None:
            self._start_registrar()
        assert self._registrar is not None
        self._registrar.join(wait)

    def _send(self, state: TopicState, now: float, msg: Any, wall: float, size: int) -> None:
        """One message under every spelling of its topic, as one instant when the monitor can."""
        if not state.aliases:
            self.submit(state.spec_name, now, msg, wall, size)
        elif self.submit_spellings is not None:
            self.submit_spellings((state.spec_name,) + state.aliases, now, msg, wall, size)
        else:
            self.submit(state.spec_name, now, msg, wall, size)
            for alias in state.aliases:  # the same message, under the spec's other spelling of the topic
                self.submit(alias, now, msg, wall, 0)

    def _callback(self, raw: Any, state: TopicState) -> None:
        """A message through rospy's own delivery (an rospy.AnyMsg, or a typed one: see message_bytes)."""
        self._on_frame(message_bytes(raw), getattr(raw, "_connection_header", None) or {}, state)

    def _on_frame(self, buff: bytes, header: Dict[str, str], state: TopicState) -> None:
        """One message of a watched topic: its serialised bytes and its connection's header."""
        wall = time.time()
        now = wall if _rostime._rostime_current is None and _rostime._rostime_initialized else ros_now()
        state.messages += 1
        if state.gone:
            return  # a reload dropped the topic; its subscription goes soon
        if not state.paths:
            self._send(state, now, None, wall, 0)  # age/frequency only: never deserialised
            return
        md5 = header.get("md5sum", "")
        md5_now, cls, type_name, unreadable = state.decoder
        if md5 != md5_now or (state.mixed is not None and wall - state.checked >= RECHECK):
            with self._types_lock:
                evaluated = topictypes.admit(state, header, wall, self._new_kind, self.log)
                kind = state.kinds.get(md5)
                cls, type_name, unreadable = ((kind.cls, kind.type, kind.unreadable) if kind is not None
                                              else (None, header.get("type", "?"), True))
            if not evaluated:
                return  # another type's message, while publishers of a type the spec can read are on
        if unreadable:  # no field the spec reads is in its type: unknown, and no data for age()/frequency()
            self._send(state, now, UNREADABLE, wall, 0)
            return
        try:
            msg = cls().deserialize(buff)  # this message's own type's class (review: not state.cls)
        except (genpy.DeserializationError, ValueError, TypeError, IndexError, Exception) as exc:
            if not state.errors or not state.errors[-1].startswith("cannot deserialise"):
                state.errors.append(f"cannot deserialise a {type_name} message: {exc}")
                self.log("error", f"topic {state.resolved}: {state.errors[-1]}")
            msg = UNKNOWN
        else:
            if state.errors and state.errors[-1].startswith("cannot deserialise"):
                state.errors.pop()  # readable again: the error lasted until this message
        self._send(state, now, msg, wall, len(buff) if msg is not UNKNOWN else 0)

    def _new_kind(self, state: TopicState, header: Dict[str, str]) -> topictypes.Kind:
        """A type not seen on this topic yet: its class, and what the rules cannot read in it (logged)."""
        type_name, md5 = header.get("type", "?"), header.get("md5sum", "")
        cls = self._class(type_name, md5, header.get("message_definition", ""))
        kind = topictypes.Kind(type_name, md5, cls, self._check(state, cls, type_name))
        kind.unreadable = self._unreadable(state, kind)
        for e in ([] if cls is not None else [f"cannot load message type {type_name}"]) + kind.problems:
            self.log("error", f"topic {state.resolved}: {e}")
        return kind

    def _check(self, state: TopicState, cls: Any, type_name: str) -> List[str]:
        """What the rules cannot read in messages of `cls` (a type_name) on this topic."""
        out = []
        for path, owners in state.paths.items():
            if path in state.implicit:
                continue  # stamp_age() of a type without header.stamp is unknown (§11), no field error
            problem = check_path(cls, path, path in state.scalar, state.needs.get(path)) \
                if cls is not None else None
            if problem:
                out.append(f"{' and '.join(owners)} reads {state.spec_name}{ast.path_suffix(path)}, but in {type_name}: "
                           f"{problem}; its value stays unknown")
        return out

    @staticmethod
    def _unreadable(state: TopicState, kind: topictypes.Kind) -> bool:
        """Whether none of the fields the spec reads on this topic can be read in `kind` (one problem
        each, or no class at all): its messages are then no data (UNREADABLE)."""
        read = sum(1 for p in state.paths if p not in state.implicit)
        return kind.cls is None or (read > 0 and len(kind.problems) >= read)

    def _class(self, type_name: str, md5: str, definition: str) -> Any:
        cls = self._classes.get(md5)
        if cls is not None:
            return cls
        try:
            cls = roslib.message.get_message_class(type_name)
        except Exception:
            cls = None
        if cls is None or getattr(cls, "_md5sum", md5) != md5:
            try:  # a type not installed here, or another version of it: build it from the publisher's definition
                cls = genpy.dynamic.generate_dynamic(type_name, definition)[type_name]
            except Exception:
                cls = None
        if cls is not None:
            self._classes[md5] = cls
        return cls

    def data_errors(self) -> List[str]:
        """What cannot be read as the spec needs now: a field missing or of the wrong kind, a
        message that cannot be deserialised, a type that cannot be loaded (not a mere type change),
        publishers of two types at once; and, with use_sim_time, a /clock that stopped (no tick
        runs ~error_actions then: it is for /diagnostics, which the main thread publishes)."""
        with self._lock:
            states = list(self.topics.values())
        out = []
        now = time.time()
        for s in states:
            if s.mixed is not None:
                with self._types_lock:
                    mixed = topictypes.refresh(s, now, self.log)
                if mixed:
                    out.append(f"topic {s.resolved}: {mixed}")
            out += [f"topic {s.resolved}: {e}" for e in s.errors if not e.startswith("changed type")]
        stall = self.clock.stalled() if self.clock is not None else ""
        return out + ([f"topic /clock: {stall}"] if stall else [])

    def status(self) -> List[TopicState]:
        with self._lock:
            return list(self.topics.values())

    def carried_types(self) -> Dict[str, Tuple[str, str]]:
        """Spec topic name (every spelling) -> (type, full definition) of the type evaluated on it."""
        out: Dict[str, Tuple[str, str]] = {}
        for s in self.status():
            text = getattr(s.cls, "_full_text", None)
            if isinstance(text, str):
                out.update({name: (s.type, text) for name in (s.spec_name,) + s.aliases})
        return out


def scalar_paths(spec: CheckedSpec) -> Dict[str, Set[Tuple[ast.PathElem, ...]]]:
    """topic -> the field paths the spec uses as one value (compared, computed with, a condition),
    rather than as the argument of a function (min, max, len of an array)."""
    out: Dict[str, Set[Tuple[ast.PathElem, ...]]] = {}
    exprs = [r.expr for r in spec.rules] + [b.cond for b in spec.behaviours]
    for expr in exprs:
        if isinstance(expr, ast.TopicRef) and expr.path:
            out.setdefault(expr.topic, set()).add(expr.path)
        for e in ast.walk(expr):
            if isinstance(e, (ast.Call, ast.ArrayFn, ast.Quant)):  # arguments of functions, array terms
                continue
            for child in ast.children(e):
                if isinstance(child, ast.TopicRef) and child.path:
                    out.setdefault(child.topic, set()).add(child.path)
    return out
