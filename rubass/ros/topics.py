"""Dynamic subscriptions: one rospy.AnyMsg subscriber per topic the spec names, whatever its
type. The type comes from each connection's header; messages are deserialised only for
topics whose fields the spec reads; field paths are checked when a topic's type is first
seen (and again when it changes)."""
from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Dict, FrozenSet, List, Optional, Set, Tuple

import genpy
import genpy.dynamic
import roslib.message
import rospy

from ..engine.values import UNKNOWN
from ..lang import ast
from ..lang.fielduse import field_needs
from ..lang.model import CheckedSpec
from .msgtypes import check_path

_rostime = rospy.rostime


def ros_now() -> float:
    """rospy.get_rostime() in seconds; on the wall clock without building a rospy.Time each time."""
    if _rostime._rostime_current is None and _rostime._rostime_initialized:
        return time.time()
    return _rostime.get_rostime().to_sec()


Submit = Callable[[str, float, Any, float, int], None]  # (spec topic, ROS time, message or None, wall, bytes)
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
    type: str = ""
    md5: str = ""
    messages: int = 0
    errors: List[str] = field(default_factory=list)
    subscriber: Optional[rospy.Subscriber] = None
    cls: Any = None


class TopicWatcher:
    def __init__(self, submit: Submit, log: Log) -> None:
        self.submit = submit
        self.log = log
        self.topics: Dict[str, TopicState] = {}  # by resolved name
        self._lock = threading.Lock()
        self._classes: Dict[str, Any] = {}  # md5 -> class

    def sync(self, spec: CheckedSpec) -> None:
        """Subscribe to the spec's topics, unsubscribe from those it no longer names."""
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
        with self._lock:
            for resolved in [r for r in self.topics if r not in wanted]:
                state = self.topics.pop(resolved)
                if state.subscriber is not None:
                    state.subscriber.unregister()
            for resolved, name in wanted.items():
                state = self.topics.get(resolved)
                aliases = tuple(spellings[resolved][1:])
                used_as_value = frozenset(p for n in spellings[resolved] for p in scalar.get(n, ()))
                needed = {p: k for n in reversed(spellings[resolved]) for p, k in needs.get(n, {}).items()}
                if state is None:
                    state = TopicState(name, resolved, users[name], aliases, used_as_value, stamp_only[name], needed)
                    self.topics[resolved] = state
                    state.subscriber = rospy.Subscriber(resolved, rospy.AnyMsg, self._callback,
                                                        callback_args=state, tcp_nodelay=True)
                else:
                    state.spec_name, state.paths, state.aliases = name, users[name], aliases
                    state.scalar, state.implicit, state.needs = used_as_value, stamp_only[name], needed
                    if state.cls is not None:
                        state.errors = self._check(state)

    def close(self) -> None:
        with self._lock:
            for state in self.topics.values():
                if state.subscriber is not None:
                    state.subscriber.unregister()
            self.topics.clear()

    def _callback(self, raw: Any, state: TopicState) -> None:
        wall = time.time()
        now = wall if _rostime._rostime_current is None and _rostime._rostime_initialized else ros_now()
        state.messages += 1
        if not state.paths:
            self.submit(state.spec_name, now, None, wall, 0)  # age/frequency only: never deserialised
            for alias in state.aliases:
                self.submit(alias, now, None, wall, 0)
            return
        header = getattr(raw, "_connection_header", None) or {}
        md5 = header.get("md5sum", "")
        if md5 != state.md5:
            self._new_type(state, header)
        if state.cls is None:
            for name in (state.spec_name,) + state.aliases:
                self.submit(name, now, UNKNOWN, wall, 0)
            return
        try:
            msg = state.cls().deserialize(raw._buff)
        except (genpy.DeserializationError, ValueError, TypeError, IndexError, Exception) as exc:
            if not state.errors or not state.errors[-1].startswith("cannot deserialise"):
                state.errors.append(f"cannot deserialise a {state.type} message: {exc}")
                self.log("error", f"topic {state.resolved}: {state.errors[-1]}")
            msg = UNKNOWN
        else:
            if state.errors and state.errors[-1].startswith("cannot deserialise"):
                state.errors.pop()  # readable again: the error lasted until this message
        self.submit(state.spec_name, now, msg, wall, len(raw._buff) if msg is not UNKNOWN else 0)
        for alias in state.aliases:  # the same message, under the spec's other spelling of the topic
            self.submit(alias, now, msg, wall, 0)

    def _new_type(self, state: TopicState, header: Dict[str, str]) -> None:
        old = state.type
        state.type, state.md5 = header.get("type", "?"), header.get("md5sum", "")
        state.cls = self._class(state.type, state.md5, header.get("message_definition", ""))
        state.errors = [] if state.cls is not None else [f"cannot load message type {state.type}"]
        state.errors += self._check(state)  # what the rules cannot read first: the status shows the first
        for e in state.errors:
            self.log("error", f"topic {state.resolved}: {e}")
        if old and old != state.type:
            self.log("error", f"topic {state.resolved} changed type from {old} to {state.type}")
            state.errors.append(f"changed type from {old} to {state.type}")

    def _check(self, state: TopicState) -> List[str]:
        out = []
        for path, owners in state.paths.items():
            if path in state.implicit:
                continue  # stamp_age() of a type without header.stamp is unknown (§11), no field error
            problem = check_path(state.cls, path, path in state.scalar, state.needs.get(path)) \
                if state.cls is not None else None
            if problem:
                out.append(f"{' and '.join(owners)} reads {state.spec_name}{ast.path_suffix(path)}, but in {state.type}: "
                           f"{problem}; its value stays unknown")
        return out

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
        message that cannot be deserialised, a type that cannot be loaded (not a mere type change)."""
        with self._lock:
            return [f"topic {s.resolved}: {e}" for s in self.topics.values() for e in s.errors
                    if not e.startswith("changed type")]

    def status(self) -> List[TopicState]:
        with self._lock:
            return list(self.topics.values())


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
