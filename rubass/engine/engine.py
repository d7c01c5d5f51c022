"""The rule engine: fed events with their times, it answers with what changed.

Time is always an argument; the engine reads no clock. Rules and behaviours form one
evaluation graph in the dependency order the checker built (§14): a message re-evaluates only
what depends on its topic, directly or through rules, behaviours and `active()`, in that order,
so a behaviour sees within the same instant the action state that others have just produced.
Stateful operators (for, within, latch, crossings of time) announce their deadlines;
`next_deadline()` tells the caller when to wake.
"""
from __future__ import annotations

import heapq
import itertools
import math
from typing import AbstractSet, Any, Callable, Dict, FrozenSet, Iterable, List, Optional, Set, Tuple

from ..lang import ast
from ..lang.model import CheckedBehaviour, CheckedSpec
from .evaluate import Compiled, Compiler
from .explain import Explainer, Witness
from .fields import FieldError, extract
from . import handover
from .events import Event, starts_first
from .operators import ForOp, LatchOp, WithinOp
from .readings import STAMP, laser_limits, stamp_seconds
from .store import Store
from .values import UNKNOWN, UNREADABLE


class _Node:
    """One rule or behaviour of the evaluation graph."""

    __slots__ = ("key", "compiled", "behaviour", "active", "value", "actions", "users", "pushed",
                 "volatile", "slots", "inputs", "fresh", "due")

    def __init__(self, key: str, compiled: Compiled, behaviour: Optional[CheckedBehaviour]) -> None:
        self.key, self.compiled, self.behaviour = key, compiled, behaviour
        self.active = False
        self.value: Any = UNKNOWN
        self.actions: Tuple[str, ...] = tuple(a.name for a in behaviour.actions) if behaviour else ()
        self.users: Set[int] = set()
        self.pushed: Dict[int, float] = {}  # id(op) -> the deadline already in the heap
        # Incremental evaluation after a message: a node that is not `volatile` is a function of
        # the fields it reads (`slots`) and of the values of other nodes (`inputs`) alone, so it
        # is skipped when none of those changed. `for`, `within` and `latch` keep it so: with
        # the same operand they give the same value until their deadline, when the engine
        # evaluates the node (`fresh`). Volatile: crossings of time, age, frequency,
        # stamp_age, rate, node samples, active(), laser limits.
        self.volatile = True
        self.slots: FrozenSet[Any] = frozenset()  # field slots while planning, then their numbers
        self.inputs: FrozenSet[int] = frozenset()
        self.fresh = True  # never evaluated yet, or its operator's deadline came (evaluated whatever changed)
        self.due = math.inf  # the earliest deadline of its operators: from then on it is not skipped

    @property
    def checked(self) -> Optional[CheckedBehaviour]:
        """The checked behaviour (None for a rule), as consumers of `orphans` read it."""
        return self.behaviour


class Engine:
    """Evaluates one checked spec over time."""

    def __init__(self, spec: CheckedSpec, now: float, origin: float = 0.0) -> None:
        """`origin`: the absolute time at which `now` is 0, when times are given relative (replay):
        header stamps are absolute, so stamp_age needs it."""
        self.spec = spec
        self.store = Store(now, origin)
        self.orphans: List[Any] = []  # active behaviours of a replaced spec that this one lacks
        self.history_lost: List[Tuple[int, str]] = []  # (behaviour, outside holder): adopt(carry=…)
        self.field_errors: Dict[Tuple[str, str], str] = {}
        # action -> [is active]; the holders: behaviour keys ('b:N') or outside holders (restored latches)
        self._active: Dict[str, List[bool]] = {a: [False] for a in spec.actions}
        self._holders: Dict[str, Set[str]] = {}
        self._compiler = Compiler(self.store, self._active)
        compiler = self._compiler  # not self in the lambda: an engine that refers to itself is freed
        # only by the cyclic garbage collector, so each one a reload replaced would linger until then
        self._explainer = Explainer(spec, self.store, lambda e: compiler._fn(e, [], None))
        self._explainer.prepare()  # a start then only reads values (it is computed before dispatch)
        order = spec.evaluation or [r.key for r in spec.rules] + [f"b:{b.index}" for b in spec.behaviours]
        rules = {r.key: r for r in spec.rules}
        self._nodes: List[_Node] = []
        for key in order:
            if key.startswith("b:"):
                b = spec.behaviours[int(key[2:]) - 1]
                self._nodes.append(_Node(key, self._compiler.compile(b.cond), b))
            else:
                self._nodes.append(_Node(key, self._compiler.compile(rules[key].expr), None))
        self._at = {n.key: i for i, n in enumerate(self._nodes)}
        self._behaviour_at = {int(n.key[2:]): i for i, n in enumerate(self._nodes) if n.behaviour}
        self._heap: List[Tuple[float, int, int, Any]] = []  # (due, seq, node index, operator)
        self._seq = itertools.count()
        self._plan_inputs(spec, now)

    # -- planning ------------------------------------------------------------------------
    def _plan_inputs(self, spec: CheckedSpec, now: float) -> None:
        windows: Dict[str, float] = {}
        topics_of: List[Set[str]] = []
        nodes_of: List[Set[str]] = []
        timed: List[int] = []
        self._rate_paths: Dict[str, List[Tuple[ast.PathElem, ...]]] = {}
        self._stamped: Set[str] = set()
        self._laser: Set[str] = set()
        readers: Dict[str, List[int]] = {}  # action -> nodes that read active(action)
        inputs: List[Set[int]] = [set() for _ in self._nodes]
        self._slot_ids: Dict[Tuple[str, Tuple[ast.PathElem, ...]], int] = {}  # field slot -> its number
        for i, node in enumerate(self._nodes):
            expr = node.behaviour.cond if node.behaviour else spec.rule(node.key).expr
            topics, nodes = set(), set()
            slots: Set[Tuple[str, Tuple[ast.PathElem, ...]]] = set()
            # `for`, `within` and `latch` give the same value again for the same operand
            # until their own deadline (where the node is evaluated whatever changed): they
            # do not make a node volatile; a crossing of time does (its value moves with now)
            volatile = any(not isinstance(op, _INSTANT_OPS) for op in node.compiled.ops)
            is_timed = False
            for e in ast.walk(expr):
                if isinstance(e, ast.TopicRef):
                    slots.add((e.topic, e.path))
                    topics.add(e.topic)
                elif isinstance(e, ast.RuleRef):
                    inputs[i].add(self._at[e.key])
                    self._nodes[self._at[e.key]].users.add(i)
                elif isinstance(e, (ast.Age, ast.Frequency, ast.StampAge)):
                    volatile = is_timed = True  # ticks re-evaluate whatever time changes
                    topics.add(e.topic)
                    if isinstance(e, ast.Frequency):
                        windows[e.topic] = max(windows.get(e.topic, 0.0), e.window)
                    if isinstance(e, ast.StampAge):
                        self._stamped.add(e.topic)
                elif isinstance(e, ast.NodeStat):
                    volatile = True
                    nodes.add(e.node)
                elif isinstance(e, ast.Rate):
                    volatile = True
                    paths = self._rate_paths.setdefault(e.ref.topic, [])
                    if e.ref.path not in paths:  # one rate per field, however many rules use it
                        paths.append(e.ref.path)
                elif isinstance(e, ast.Active):
                    volatile = True
                    readers.setdefault(e.action, []).append(i)
                elif isinstance(e, ast.ArrayFn) and e.ref.path[:1] == ("ranges",):
                    volatile = True  # reads the scan's range limits too
                    self._laser.add(e.ref.topic)
            if is_timed:
                timed.append(i)
            topics_of.append(topics)
            nodes_of.append(nodes)
            node.volatile, node.slots, node.inputs = volatile, frozenset(slots), frozenset(inputs[i])
        for node in self._nodes:
            for action in node.actions:
                node.users.update(readers.get(action, ()))
        self._readers = readers
        self._released = False  # a release was emitted since the last _ordered()
        for topic in spec.topics:
            self.store.watch(topic, now, windows.get(topic, 0.0))
        explicit = spec.field_readers(implicit=False)  # header.stamp as a field, not only for stamp_age
        self._paths = {t: tuple(sorted((p for p in u.paths if p != STAMP or STAMP in explicit.get(t, ())), key=str))
                       for t, u in spec.topics.items()}  # rate fields too
        # per topic: (slot number, store slot, its cell, path, its key in field_errors), computed once
        self._reads = {t: tuple((self._slot_ids.setdefault((t, p), len(self._slot_ids)), (t, p),
                                 self.store.cell((t, p)), p, str(p)) for p in paths)
                       for t, paths in self._paths.items()}
        for node in self._nodes:
            node.slots = frozenset(self._slot_ids.setdefault(s, len(self._slot_ids)) for s in node.slots)
        self._topic_plans = {t: self._plan([i for i, s in enumerate(topics_of) if t in s]) for t in spec.topics}
        self._node_plans = {n: self._plan([i for i, s in enumerate(nodes_of) if n in s]) for n in spec.nodes}
        self._tick_plan = self._plan(timed)
        self._batch_plans: Dict[Tuple[str, ...], Tuple[int, ...]] = {}  # topics of a batch -> its plan
        self._all = tuple(range(len(self._nodes)))

    def _plan(self, seeds: Iterable[int]) -> Tuple[int, ...]:
        """The seeds and everything that uses them, in evaluation order."""
        seen: Set[int] = set()
        stack = list(seeds)
        while stack:
            i = stack.pop()
            if i not in seen:
                seen.add(i)
                stack.extend(self._nodes[i].users)
        return tuple(sorted(seen))

    # -- inputs --------------------------------------------------------------------------
    def on_message(self, topic: str, now: float, msg: Any = None) -> List[Event]:
        """A message on a watched topic; msg None when only its arrival matters."""
        return self.on_messages(now, ((topic, msg),))

    def on_messages(self, now: float, items: Iterable[Tuple[str, Any]]) -> List[Event]:
        """Messages that share one instant (as in a recording): one evaluation after all of them.

        Evaluating between them would see a state that never existed at any instant (one
        topic updated, the other not yet) and could restart a `for`.
        """
        events = self._advance(now, inclusive=False)
        changed: Set[int] = set()  # the numbers of the field slots whose value changed
        if isinstance(items, tuple) and len(items) == 1:  # the live case: one message, its own plan
            topic, msg = items[0]
            self._store_message(topic, now, msg, changed)
            plan = self._with_due(self._topic_plans.get(topic), now)
            if plan:
                self._run(plan, events, changed)
            events += self._advance(now)
            return self._ordered(events)
        topics = []
        for topic, msg in items:
            self._store_message(topic, now, msg, changed)
            topics.append(topic)
        key = tuple(topics)
        plan = self._batch_plans.get(key)
        if plan is None:  # a recording repeats the same few batches of topics: planned once each
            if len(self._batch_plans) >= 4096:
                self._batch_plans.clear()
            seeds: Set[int] = set()
            for topic in key:
                seeds.update(self._topic_plans.get(topic, ()))
            plan = self._batch_plans[key] = tuple(sorted(seeds))
        plan = self._with_due(plan, now)
        if plan:
            self._run(plan, events, changed)
        events += self._advance(now)
        return self._ordered(events)

    def _with_due(self, plan: Optional[Tuple[int, ...]], now: float) -> Optional[Tuple[int, ...]]:
        """An input's plan with the nodes whose deadline falls at its very instant (and their users):
        one evaluation at `now`, with the new data and every `for` due then. Apart, a rule using a
        `for` due at t read its old value with t's message, and a `for` over it restarted
        (test_for_reference: `(a < 1 or r0) for 1 s` fell for 1 s as r0 came true with a's message)."""
        due: List[int] = []
        while True:
            at = self.next_deadline()
            if at is None or at > now:
                break
            _, _, idx, _ = heapq.heappop(self._heap)
            self._nodes[idx].fresh = True  # its operator's instant: evaluated whatever else changed
            due.append(idx)
        if not due:
            return plan
        return tuple(sorted(set(plan or ()) | set(self._plan(due))))

    def _store_message(self, topic: str, now: float, msg: Any, changed: Set[Any]) -> None:
        store = self.store
        data = msg is not UNREADABLE  # not data: a dead sensor beside a publisher of another type goes stale
        if data:
            store.arrive(topic, now)
        else:
            msg = UNKNOWN
        fields = store.fields
        for number, slot, cell, path, key in self._reads.get(topic, ()):
            value = self._read(topic, path, msg, key)
            old = cell[0]
            if value is not old and (value != old or type(value) is not type(old)):
                changed.add(number)
                cell[0] = fields[slot] = value
        for path in self._rate_paths.get(topic, ()):  # read above, as a plain field
            store.arrive_rate(topic, path, now, store.fields.get((topic, path), UNKNOWN))
        if topic in self._stamped and data:  # stamp_age goes on from the last readable stamp
            try:
                stamp = UNKNOWN if msg is UNKNOWN else stamp_seconds(extract(msg, STAMP, raw=True))
            except FieldError:
                stamp = UNKNOWN  # a type with no header.stamp: stamp_age is unknown (§11)
            store.stamps[topic] = stamp
        if topic in self._laser and data:
            store.laser_limits[topic] = laser_limits(msg)

    def _read(self, topic: str, path: Tuple[ast.PathElem, ...], msg: Any, key: str) -> Any:
        if msg is UNKNOWN:  # the shell could not read it: its fields are missing data
            return UNKNOWN
        try:
            value = extract(msg, path)
        except FieldError as exc:
            self.field_errors[(topic, key)] = str(exc)
            return UNKNOWN
        if self.field_errors:
            self.field_errors.pop((topic, key), None)
        return value

    def on_node_sample(self, node: str, now: float, alive: Any, cpu: Any = UNKNOWN, memory: Any = UNKNOWN) -> List[Event]:
        """A sample of a node: alive True/False/UNKNOWN, cpu share of a core, memory bytes."""
        events = self._advance(now, inclusive=False)
        self.store.nodes[node] = {"alive": alive, "cpu": cpu, "memory": memory}
        plan = self._with_due(self._node_plans.get(node), now)
        if plan:
            self._run(plan, events, _NO_FIELDS)
        events += self._advance(now)
        return self._ordered(events)

    def on_tick(self, now: float) -> List[Event]:
        """A scheduler tick: time-dependent expressions, then `hold` of every active behaviour."""
        events = self._advance(now)
        self._run(self._tick_plan, events, _NO_FIELDS)
        for node in self._nodes:
            if node.active:
                events.append(self._event(node, "hold"))
        return self._ordered(events)

    def evaluate_all(self, now: float) -> List[Event]:
        """Evaluate every rule and behaviour (at start, and after a reload)."""
        events = self._advance(now)
        self._run(self._all, events)
        return self._ordered(events)

    def advance(self, now: float, inclusive: bool = True) -> List[Event]:
        """Fire every deadline up to `now` (before it, if not inclusive), each at its own instant.

        Inputs call this non-inclusively first: new data at t is the evaluation at t, so a
        `for` that a message at t falsifies never fires at t with the old data.
        """
        return self._ordered(self._advance(now, inclusive))

    def _advance(self, now: float, inclusive: bool = True) -> List[Event]:
        events: List[Event] = []
        while True:
            due = self.next_deadline()
            if due is None or not (due <= now if inclusive else due < now):
                break
            _, _, idx, _ = heapq.heappop(self._heap)
            self.store.now = max(self.store.now, due)
            self._nodes[idx].fresh = True  # its operator's instant: evaluated whatever else changed
            self._run(self._plan((idx,)), events, _NO_FIELDS)
        self.store.now = max(self.store.now, now)
        return events

    def _ordered(self, events: List[Event]) -> List[Event]:
        """starts_first(events) when a release was emitted since the last call; else as they are."""
        if not self._released:
            return events
        self._released = False
        return starts_first(events)

    def next_deadline(self) -> Optional[float]:
        """The next instant a value changes by itself: a `for`, `within`, a crossing of time."""
        heap = self._heap
        while heap:
            due, _, idx, op = heap[0]
            if op.deadline() == due:
                return due
            heapq.heappop(heap)  # its cause changed since: nothing happens then
            self._nodes[idx].pushed.pop(id(op), None)
        return None

    # -- actions -------------------------------------------------------------------------
    def reset(self, now: float) -> List[Event]:
        """Release latched behaviours whose condition is no longer true, and outside holders."""
        events = self.advance(now)
        released: List[int] = []
        for i, node in enumerate(self._nodes):
            if node.active and node.value is not True:
                node.active = False
                for a in node.actions:  # active() of its actions ends with it
                    self._holders.get(a, set()).discard(node.key)
                released.append(i)
                events.append(self._event(node, "release"))
        for action in list(self._holders):
            self._holders[action] = {h for h in self._holders[action] if h.startswith("b:")}
        self._sync_actions()
        seeds = [u for i in released for u in self._nodes[i].users]
        seeds += [r for a in self._readers for r in self._readers[a]]
        if seeds:
            self._run(self._plan(seeds), events)
        return self._ordered(events)

    def hold_actions(self, actions: Iterable[str], holder: str, now: float) -> List[Event]:
        """Make actions active on behalf of an outside holder (a latch restored after a restart),
        until reset; nodes reading active() of them are evaluated at once."""
        events = self.advance(now)
        for a in actions:
            self._holders.setdefault(a, set()).add(holder)
        self._sync_actions()
        seeds = [r for a in actions for r in self._readers.get(a, ())]
        if seeds:
            self._run(self._plan(seeds), events)
        return self._ordered(events)

    def release_holder(self, holder: str, now: float) -> List[Event]:
        """End an outside holder's hold on every action (before ~reset); readers of active() run."""
        events = self.advance(now)
        touched = [a for a, hs in self._holders.items() if holder in hs]
        for a in touched:
            self._holders[a].discard(holder)
        self._sync_actions()
        seeds = [r for a in touched for r in self._readers.get(a, ())]
        if seeds:
            self._run(self._plan(seeds), events)
        return self._ordered(events)

    def outside_holders(self) -> Dict[str, Tuple[str, ...]]:
        """Holders other than this spec's behaviours (restored latches, …) and the actions they hold."""
        out: Dict[str, List[str]] = {}
        for action, holders in self._holders.items():
            for h in holders:
                if not h.startswith("b:"):
                    out.setdefault(h, []).append(action)
        return {h: tuple(sorted(a)) for h, a in out.items()}

    def active_actions(self) -> Dict[str, Tuple[str, ...]]:
        """Each active action and who holds it: behaviour names ('behaviour N' when unnamed) or outside holders."""
        out: Dict[str, Tuple[str, ...]] = {}
        for action, holders in self._holders.items():
            if holders:
                out[action] = tuple(sorted(self._holder_label(h) for h in holders))
        return out

    def _holder_label(self, holder: str) -> str:
        if holder.startswith("b:"):
            return self.spec.behaviours[int(holder[2:]) - 1].label
        return holder

    def _sync_actions(self) -> None:
        for action, flag in self._active.items():
            flag[0] = bool(self._holders.get(action))

    # -- live reload ---------------------------------------------------------------------
    def adopt(self, old: "Engine", now: float,
              carry: Optional[Callable[[CheckedBehaviour], str]] = None) -> List[Event]:
        """Take over the state of the engine this one replaces, then evaluate everything (handover.py)."""
        return handover.adopt(self, old, now, carry)

    # -- state ---------------------------------------------------------------------------
    def rule_value(self, key: str) -> Any:
        return self.store.rules.get(key, UNKNOWN)

    def behaviour_rules(self, index: int) -> List[str]:
        """The rules a behaviour's condition names that are true now (what caused it)."""
        cond = self.spec.behaviours[index - 1].cond
        keys = [e.key for e in ast.walk(cond) if isinstance(e, ast.RuleRef)]
        return sorted({k for k in keys if self.store.rules.get(k) is True})

    def explain(self, index: int) -> Witness:
        """Why behaviour `index` (1-based) holds now: read at its start only, just before it is dispatched."""
        return self._explainer.explain(index)

    def active_behaviours(self) -> List[int]:
        return sorted(int(n.key[2:]) for n in self._nodes if n.behaviour and n.active)

    # -- evaluation ----------------------------------------------------------------------
    def _event(self, node: _Node, kind: str, witness: Optional[Witness] = None) -> Event:
        b = node.behaviour
        assert b is not None
        return Event(self.store.now, kind, b.index, actions=node.actions, line=b.span.line, name=b.name,
                     witness=witness)

    def _run(self, plan: Tuple[int, ...], events: List[Event], changed: Optional[AbstractSet[int]] = None) -> None:
        """Evaluate the plan's nodes in order. After a message, a tick, a deadline or a node
        sample (`changed`: the numbers of the field slots it changed, if any), a node that is
        not volatile is skipped when neither a field it reads nor a node it reads changed
        value: it would give the value it has. With `changed` None, every node is evaluated."""
        store, nodes, rules = self.store, self._nodes, self.store.rules
        moved: Set[int] = set()  # nodes whose value changed in this run
        incremental, now = changed is not None, store.now
        for i in plan:
            node = nodes[i]
            if incremental and not node.volatile and not node.fresh and node.due > now \
                    and changed.isdisjoint(node.slots) and moved.isdisjoint(node.inputs):  # type: ignore[union-attr]
                continue
            node.fresh = False
            compiled = node.compiled
            value = compiled.fn()
            if compiled.ops:  # _schedule, inline: the deadlines its operators announce now
                pushed, first = node.pushed, math.inf
                for op in compiled.ops:
                    due = op.deadline()
                    if due is not None:
                        if due < first:
                            first = due
                        if pushed.get(id(op)) != due:
                            pushed[id(op)] = due
                            heapq.heappush(self._heap, (due, next(self._seq), i, op))
                node.due = first
            b = node.behaviour
            if b is None:
                key = node.key
                old = rules.get(key, _ABSENT)
                if value is not old:  # rule values are True, False or UNKNOWN: identity is equality
                    rules[key] = value
                    moved.add(i)
                    events.append(Event(store.now, "rule", rule=key, value=None if value is UNKNOWN else value))
                continue
            if value is not node.value:  # True, False or UNKNOWN
                moved.add(i)
            node.value = value
            if value is True and not node.active:
                node.active = True
                for a in node.actions:
                    self._holders.setdefault(a, set()).add(node.key)
                self._sync_actions()
                events.append(self._event(node, "start", self.explain(b.index)))
            elif value is not True and node.active and not b.latched:
                node.active = False
                for a in node.actions:
                    self._holders.get(a, set()).discard(node.key)
                self._sync_actions()
                events.append(self._event(node, "release"))
                self._released = True

    def _schedule(self, idx: int, node: _Node) -> None:
        deadlines = node.compiled.deadlines()
        node.due = min((due for due, _ in deadlines), default=math.inf)
        for due, op in deadlines:
            if node.pushed.get(id(op)) != due:
                node.pushed[id(op)] = due
                heapq.heappush(self._heap, (due, next(self._seq), idx, op))


_ABSENT = object()  # a rule not evaluated yet
_INSTANT_OPS = (ForOp, WithinOp, LatchOp)  # operators whose value moves only at inputs and deadlines
_NO_FIELDS: FrozenSet[int] = frozenset()  # a tick, a deadline, a node sample: no field changed
