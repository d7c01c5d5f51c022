"""From engine events to actions: each start, hold and release goes to the runners of the
behaviour's actions, and each start and release is reported on ~events with its latency.

Runs on the engine's thread; it only hands over (runners never block it)."""
from __future__ import annotations

import time
from typing import Any, Callable, Dict, List, Optional

from ..engine import Engine, Event
from ..engine.loop import Message, NodeSample
from ..lang.fmt import format_attrs
from ..lang.model import CheckedBehaviour
from .base import Context
from .runner import ActionRunner

Report = Callable[[Dict[str, Any]], None]


class Dispatcher:
    def __init__(self, runners: Dict[str, ActionRunner], report: Report, ros_now: Callable[[], float],
                 topic_name: Callable[[str], str] = str) -> None:
        """`topic_name`: the name a spec's topic or node has on the robot (namespace and remappings applied),
        as a start's `cause` names it."""
        self.runners = runners
        self.report = report
        self.ros_now = ros_now
        self.topic_name = topic_name
        self.latencies: List[float] = []  # seconds, last 1000 starts
        self.last_start = "none"  # the last start and why, for /diagnostics
        self.orphans: List[Any] = []  # (behaviour, key): latched, from a spec a reload replaced
        self._keys_for: Any = None
        self._keys: Dict[int, Any] = {}

    @staticmethod
    def keys(behaviours: List[CheckedBehaviour]) -> Dict[int, Any]:
        """Each behaviour's identity across reloads (as the engine carries it: by name and actions,
        unnamed by condition and actions), numbered among identical twins."""
        seen: Dict[str, int] = {}
        out: Dict[int, Any] = {}
        for b in behaviours:
            seen[b.identity] = seen.get(b.identity, 0) + 1
            out[b.index] = (b.identity, seen[b.identity])
        return out

    def handle(self, engine: Engine, events: List[Event], cause: Any) -> None:
        spec = engine.spec
        for e in events:  # first claim every start's actions: of actions that start in one instant on
            if e.kind == "start":  # one topic, the highest priority owns it before any runner publishes
                for bound in spec.behaviours[e.behaviour - 1].actions:
                    runner = self.runners.get(bound.name)
                    if runner is not None:
                        runner.claim()
        for e in events:
            if e.kind not in ("start", "hold", "release"):
                continue
            b = spec.behaviours[e.behaviour - 1]
            rules = tuple(engine.behaviour_rules(e.behaviour)) if e.kind != "hold" else ()
            self.send(e.kind, b, Context(e.behaviour, b.span.line, rules, (), e.time, self.keys_of(spec)[e.behaviour]))
            if e.kind != "hold":
                self.report_event(e, b, rules, cause)

    def keys_of(self, spec: Any) -> Dict[int, Any]:
        if self._keys_for is not spec:
            self._keys_for, self._keys = spec, self.keys(spec.behaviours)
        return self._keys

    def send(self, kind: str, b: CheckedBehaviour, ctx: Context,
             runners: Optional[Dict[str, ActionRunner]] = None) -> None:
        for bound in b.actions:
            runner = (self.runners if runners is None else runners).get(bound.name)
            if runner is not None:
                runner.submit(kind, Context(ctx.behaviour, ctx.line, ctx.rules, bound.args, ctx.time, ctx.key))

    def report_event(self, e: Event, b: CheckedBehaviour, rules: tuple, cause: Any) -> None:
        latency: Optional[float]
        if isinstance(cause, Message) and cause.received:
            source, latency = f"message on {self.topic_name(cause.topic)}", time.time() - cause.received
        elif isinstance(cause, NodeSample):  # from the sample's instant, or the deadline it came with
            source, latency = f"node sample of {self.topic_name(cause.node)}", max(0.0, self.ros_now() - e.time)
        elif cause == "reset":
            source, latency = "reset service", None
        elif cause in ("reload", "shutdown"):
            source, latency = cause, None
        else:
            source, latency = "deadline", max(0.0, self.ros_now() - e.time)
        if e.kind == "start" and latency is not None:
            self.latencies.append(latency)
            del self.latencies[:-1000]
        record: Dict[str, Any] = {
            "time": e.time, "event": e.kind, "behaviour": e.behaviour, "line": b.span.line,
            "actions": [a.name for a in b.actions], "rules": list(rules), "cause": source,
            "latency_ms": None if latency is None else round(latency * 1000.0, 3),
        }
        if b.name:  # starts and releases alike carry the behaviour's name and attributes (§14, §15)
            record["name"] = b.name
        if b.attrs:
            record["attrs"] = {k: list(v) for k, v in b.attrs.items()}
        witness = getattr(e, "witness", None)
        if witness is not None:  # why it started: name, attributes, true rules and the values they read
            record.update(witness.as_json())
            why = "; ".join([witness.causes()] * bool(witness.causes()) + [r.text() for r in witness.readings])
            who = (witness.name or f"behaviour {e.behaviour}") + (f" {format_attrs(b.attrs)}" if b.attrs else "")
            self.last_start = f"{who} at {e.time:.3f} s" + (f": {why}" if why else "")
        self.report(record)

    def release(self, b: CheckedBehaviour, key: Any, now: float,
                runners: Optional[Dict[str, ActionRunner]] = None) -> None:
        """Release a behaviour's actions outside an engine event (reload, reset, shutdown); `runners`
        instead of the dispatcher's own (a reload: the new ones, and the old of actions gone)."""
        self.send("release", b, Context(b.index, b.span.line, (), (), now, key), runners)

    def release_orphans(self, now: float) -> None:
        """Release latched actions of behaviours that a reload removed (called by ~reset)."""
        for b, key in self.orphans:
            self.release(b, key, now)
        self.orphans = []
