"""The rule engine: fed events with their times, it answers with what changed.

Time is always an argument; the engine reads no clock. A message re-evaluates only the rules
that depend on its topic (and the rules and behaviours that use those), in dependency order.
`for` timers report their deadlines; `next_deadline()` tells the caller when to wake.
"""
from __future__ import annotations

import functools
import heapq
import itertools
from dataclasses import dataclass
from typing import Any, Dict, Iterable, List, Optional, Set, Tuple

from ..lang import ast
from ..lang.model import CheckedBehaviour, CheckedSpec
from .evaluate import Compiled, Compiler
from .explain import Explainer, Witness
from .fields import FieldError, extract
from .store import Store
from .temporal import ForTimer
from .values import UNKNOWN


@dataclass(frozen=True)
class Event:
    """A change: a behaviour's start/hold/release, or a rule's new value ('rule')."""

    time: float
    kind: str
    behaviour: int = 0  # 1-based, in file order
    rule: str = ""
    value: Any = None
    actions: Tuple[str, ...] = ()
    line: int = 0
    name: str = ""  # the behaviour's name (§14), "" when unnamed
    witness: Optional[Witness] = None  # at a start: the true rules and the values they read (explain.py)


@dataclass
class _Plan:
    """What one kind of input makes the engine re-evaluate, in dependency order."""

    rules: Tuple[int, ...]
    behaviours: Tuple[int, ...]


class _Behaviour:
    def __init__(self, checked: CheckedBehaviour, compiled: Compiled) -> None:
        self.checked, self.compiled = checked, compiled
        self.active = False
        self.value: Any = UNKNOWN
        self.actions = tuple(a.name for a in checked.actions)


class Engine:
    """Evaluates one checked spec over time."""

    def __init__(self, spec: CheckedSpec, now: float) -> None:
        self.spec = spec
        self.store = Store(now)
        self.orphans: List[_Behaviour] = []  # active behaviours of a replaced spec that this one lacks
        self.field_errors: Dict[Tuple[str, str], str] = {}
        self._explainer: Optional[Explainer] = None
        compiler = Compiler(self.store)
        self._keys = [r.key for r in spec.rules]
        self._index = {k: i for i, k in enumerate(self._keys)}
        self._rules = [compiler.compile(r.expr) for r in spec.rules]
        self._behaviours = [_Behaviour(b, compiler.compile(b.cond)) for b in spec.behaviours]
        self._paths = {t: tuple(sorted(u.paths, key=str)) for t, u in spec.topics.items()}
        # (due, seq, kind 0 rule / 1 behaviour, index, the ForTimer or None, its start)
        self._heap: List[Tuple[float, int, int, int, Optional[ForTimer], float]] = []
        self._seq = itertools.count()
        self._timed_pushed: Dict[Tuple[int, int], Set[float]] = {}
        for kind, compiled_list in ((0, self._rules), (1, [b.compiled for b in self._behaviours])):
            for idx, compiled in enumerate(compiled_list):
                for timer in compiled.timers:
                    timer.notify = functools.partial(self._push_timer, kind, idx)
        windows: Dict[str, float] = {}
        direct: List[Tuple[Set[str], Set[str], bool]] = []
        for expr in [r.expr for r in spec.rules] + [b.cond for b in spec.behaviours]:
            topics, nodes, timed = set(), set(), False
            for e in ast.walk(expr):
                if isinstance(e, ast.TopicRef):
                    topics.add(e.topic)
                elif isinstance(e, ast.NodeRef):
                    nodes.add(e.node)
                elif isinstance(e, ast.Call) and e.func in ("age", "frequency"):
                    timed = True
                    if e.func == "frequency":
                        w = e.args[1].value if len(e.args) > 1 else 1.0  # type: ignore[union-attr]
                        t = e.args[0].topic  # type: ignore[union-attr]
                        windows[t] = max(windows.get(t, 0.0), float(w))  # type: ignore[arg-type]
            direct.append((topics, nodes, timed))
        for topic in spec.topics:
            self.store.watch(topic, now, windows.get(topic, 0.0))
        self._users = self._rule_users(spec)
        n = len(self._rules)
        self._topic_plans = {t: self._plan([i for i, d in enumerate(direct) if t in d[0]]) for t in spec.topics}
        self._node_plans = {nd: self._plan([i for i, d in enumerate(direct) if nd in d[1]]) for nd in spec.nodes}
        self._tick_plan = self._plan([i for i, d in enumerate(direct) if d[2]])
        self._rule_plans = [self._plan([i]) for i in range(n)]
        self._all = self._plan(list(range(n + len(self._behaviours))))

    # -- planning ------------------------------------------------------------------------
    def _rule_users(self, spec: CheckedSpec) -> List[Set[int]]:
        users: List[Set[int]] = [set() for _ in spec.rules]
        n = len(spec.rules)
        for i, r in enumerate(spec.rules):
            for dep in r.rule_deps:
                users[self._index[dep]].add(i)
        for j, b in enumerate(spec.behaviours):
            for e in ast.walk(b.cond):
                if isinstance(e, ast.RuleRef):
                    users[self._index[e.key]].add(n + j)
        return users

    def _plan(self, seeds: List[int]) -> _Plan:
        """Seeds (rule indices, then n + behaviour index) and everything that uses them."""
        n = len(self._rules)
        seen: Set[int] = set()
        stack = list(seeds)
        while stack:
            i = stack.pop()
            if i in seen:
                continue
            seen.add(i)
            if i < n:
                stack.extend(self._users[i])
        return _Plan(tuple(sorted(i for i in seen if i < n)), tuple(sorted(i - n for i in seen if i >= n)))

    # -- inputs --------------------------------------------------------------------------
    def on_message(self, topic: str, now: float, msg: Any = None) -> List[Event]:
        """A message on a watched topic; msg None when only its arrival matters."""
        return self.on_messages(now, ((topic, msg),))

    def on_messages(self, now: float, items: Iterable[Tuple[str, Any]]) -> List[Event]:
        """Messages that share one instant (as in a recording): one evaluation after all of them.

        Evaluating between them would see a state that never existed at any instant (one
        topic updated, the other not yet) and could restart a `for`.
        """
        events = self.advance(now, inclusive=False)
        if isinstance(items, tuple) and len(items) == 1:  # the live case: one message, its own plan
            topic, msg = items[0]
            self._store_message(topic, now, msg)
            plan = self._topic_plans.get(topic)
            if plan is not None:
                self._run(plan, events)
            events += self.advance(now)
            return events
        rules: Set[int] = set()
        behaviours: Set[int] = set()
        for topic, msg in items:
            self._store_message(topic, now, msg)
            plan = self._topic_plans.get(topic)
            if plan is not None:
                rules.update(plan.rules)
                behaviours.update(plan.behaviours)
        if rules or behaviours:
            self._run(_Plan(tuple(sorted(rules)), tuple(sorted(behaviours))), events)
        events += self.advance(now)
        return events

    def _store_message(self, topic: str, now: float, msg: Any) -> None:
        self.store.arrive(topic, now)
        for path in self._paths.get(topic, ()):
            if msg is UNKNOWN:  # the shell could not read it: its fields are missing data
                self.store.fields[(topic, path)] = UNKNOWN
                continue
            try:
                value = extract(msg, path)
                self.field_errors.pop((topic, str(path)), None)
            except FieldError as exc:
                value = UNKNOWN
                self.field_errors[(topic, str(path))] = str(exc)
            self.store.fields[(topic, path)] = value

    def on_node_sample(self, node: str, now: float, alive: Any, cpu: Any = UNKNOWN, memory: Any = UNKNOWN) -> List[Event]:
        """A sample of a node: alive True/False/UNKNOWN, cpu share of a core, memory bytes."""
        events = self.advance(now, inclusive=False)
        self.store.nodes[node] = {"alive": alive, "cpu": cpu, "memory": memory}
        plan = self._node_plans.get(node)
        if plan is not None:
            self._run(plan, events)
        events += self.advance(now)
        return events

    def on_tick(self, now: float) -> List[Event]:
        """A scheduler tick: time-dependent rules (age, frequency), then `hold` of every active behaviour."""
        events = self.advance(now)
        self._run(self._tick_plan, events)
        for j, b in enumerate(self._behaviours):
            if b.active:
                events.append(Event(now, "hold", j + 1, actions=b.actions, line=b.checked.span.line))
        return events

    def evaluate_all(self, now: float) -> List[Event]:
        """Evaluate every rule and behaviour (at start, and after a reload)."""
        events = self.advance(now)
        self._run(self._all, events)
        return events

    def advance(self, now: float, inclusive: bool = True) -> List[Event]:
        """Fire every deadline up to `now` (before it, if not inclusive), each at its own instant.

        Inputs call this non-inclusively first: new data at t is the evaluation at t, so a
        `for` that a message at t falsifies never fires at t with the old data.
        """
        events: List[Event] = []
        while True:
            due = self.next_deadline()
            if due is None or not (due <= now if inclusive else due < now):
                break
            _, _, kind, idx, _, _ = heapq.heappop(self._heap)
            self.store.now = max(self.store.now, due)
            if kind == 0:
                self._run(self._rule_plans[idx], events)
            else:
                self._run(_Plan((), (idx,)), events)
        self.store.now = max(self.store.now, now)
        return events

    def next_deadline(self) -> Optional[float]:
        """The next instant a value changes by itself: a `for`, an age crossing, a frequency window."""
        heap = self._heap
        while heap:
            due, _, kind, idx, timer, since = heap[0]
            if timer is not None:
                if timer.since == since:
                    return due
            else:
                compiled = self._rules[idx] if kind == 0 else self._behaviours[idx].compiled
                if due in compiled.time_deadlines(self.store, strict=False):
                    return due
            heapq.heappop(heap)  # its cause changed since: nothing happens then
        return None

    def _push_timer(self, kind: int, idx: int, due: float, timer: ForTimer, since: float) -> None:
        heapq.heappush(self._heap, (due, next(self._seq), kind, idx, timer, since))

    def reset(self, now: float) -> List[Event]:
        """Release latched behaviours whose condition is no longer true."""
        events = self.advance(now)
        for j, b in enumerate(self._behaviours):
            if b.active and b.value is not True:
                b.active = False
                events.append(Event(now, "release", j + 1, actions=b.actions, line=b.checked.span.line))
        return events

    # -- live reload ---------------------------------------------------------------------
    def adopt(self, old: "Engine", now: float) -> List[Event]:
        """Take over the state of the engine this one replaces, then evaluate everything.

        Data (fields, arrivals, node samples) carries over for topics and nodes both specs
        use; a rule whose text and whose used rules' texts are unchanged keeps its value and
        its `for` timers; a behaviour with an unchanged condition and actions keeps its state
        (an active one does not start again). Topics new to this spec are watched from now.
        Returns the events of the first evaluation. Call it on the engine's thread.
        """
        old.advance(now)
        src, dst = old.store, self.store
        for topic in self.spec.topics:
            if topic in old.spec.topics:
                dst.watch_start[topic] = src.watch_start[topic]
                if topic in src.last_arrival:
                    dst.last_arrival[topic] = src.last_arrival[topic]
                dst.carry_arrivals(src, topic)
            else:
                dst.watch_start[topic] = now
        dst.fields.update({k: v for k, v in src.fields.items() if k[0] in self.spec.topics})
        dst.nodes.update({n: v for n, v in src.nodes.items() if n in self.spec.nodes})
        dst.now = max(dst.now, now)
        old_rules = {r.key: (r.signature, old._rules[i]) for i, r in enumerate(old.spec.rules)}
        for i, r in enumerate(self.spec.rules):
            prev = old_rules.get(r.key)
            if prev is not None and prev[0] == r.signature:
                self._take_timers(prev[1], self._rules[i])
                if r.key in src.rules:
                    dst.rules[r.key] = src.rules[r.key]
        old_behaviours = {b.checked.signature: b for b in old._behaviours}
        for b in self._behaviours:
            prev_b = old_behaviours.pop(b.checked.signature, None)
            if prev_b is not None:
                self._take_timers(prev_b.compiled, b.compiled)
                b.active, b.value = prev_b.active, prev_b.value
        self.orphans = [b for b in old_behaviours.values() if b.active]
        return self.evaluate_all(now)

    def _take_timers(self, src: Compiled, dst: Compiled) -> None:
        for a, b in zip(src.timers, dst.timers):
            b.since = a.since
            if a.since is not None and b.duration > 0:
                self._push_timer(*b.notify.args, a.since + b.duration, b, a.since)  # type: ignore[union-attr]

    # -- state ---------------------------------------------------------------------------
    def rule_value(self, key: str) -> Any:
        return self.store.rules.get(key, UNKNOWN)

    def behaviour_rules(self, index: int) -> List[str]:
        """The rules a behaviour's condition names that are true now (what caused it)."""
        cond = self._behaviours[index - 1].checked.cond
        keys = [e.key for e in ast.walk(cond) if isinstance(e, ast.RuleRef)]
        return sorted({k for k in keys if self.store.rules.get(k) is True})

    def explain(self, index: int) -> Witness:
        """Why behaviour `index` (1-based) holds now: computed at its start only, off the message path."""
        if self._explainer is None:
            self._explainer = Explainer(self.spec, self.store, lambda e: Compiler(self.store)._fn(e, []))
        return self._explainer.explain(index)

    def active_behaviours(self) -> List[int]:
        return [j + 1 for j, b in enumerate(self._behaviours) if b.active]

    # -- evaluation ----------------------------------------------------------------------
    def _run(self, plan: _Plan, events: List[Event]) -> None:
        store, now = self.store, self.store.now
        for i in plan.rules:
            compiled = self._rules[i]
            value = compiled.fn()
            key = self._keys[i]
            old = store.rules.get(key, UNKNOWN)
            if value is not old and value != old or key not in store.rules:
                store.rules[key] = value
                events.append(Event(now, "rule", rule=key, value=None if value is UNKNOWN else value))
            self._schedule(compiled, 0, i)
        for j in plan.behaviours:
            b = self._behaviours[j]
            b.value = b.compiled.fn()
            self._schedule(b.compiled, 1, j)
            if b.value is True and not b.active:
                b.active = True
                events.append(Event(now, "start", j + 1, actions=b.actions, line=b.checked.span.line,
                                    witness=self.explain(j + 1)))
            elif b.value is not True and b.active and not b.checked.latched:
                b.active = False
                events.append(Event(now, "release", j + 1, actions=b.actions, line=b.checked.span.line))

    def _schedule(self, compiled: Compiled, kind: int, idx: int) -> None:
        if compiled.timed:
            pushed = self._timed_pushed.setdefault((kind, idx), set())
            for due in compiled.time_deadlines(self.store):
                if due not in pushed:
                    if len(pushed) > 64:  # forget old ones; a repeat push is only wasted work
                        pushed.clear()
                    pushed.add(due)
                    heapq.heappush(self._heap, (due, next(self._seq), kind, idx, None, 0.0))
