"""Evaluating checked expressions: each AST node becomes a small Python closure once, when
the engine is built, so a message costs only calls, never a tree walk or an `eval`. Operators
and functions mean what rubass.lang.ops says, as in the checker's constant folding."""
from __future__ import annotations

import math
import operator
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

from ..lang import ast
from ..lang.geometry import boundary_distance, inside
from ..lang.ops import BINARY, UNARY, scalar_fn
from .arrays import array_fn, element, quantifier
from .operators import ForOp, LatchOp, WithinOp
from .store import Store
from .timeflow import crossings
from .values import UNKNOWN, as_bool, as_num, k_and, k_or

Fn = Callable[[], Any]


class Compiled:
    """A compiled condition: its function and its stateful operators (for, within, latch and
    the crossings of time), each announcing its own deadline."""

    def __init__(self, fn: Fn, ops: List[Any]) -> None:
        self.fn, self.ops = fn, ops

    def deadlines(self) -> List[Tuple[float, Any]]:
        out = []
        for op in self.ops:
            due = op.deadline()
            if due is not None:
                out.append((due, op))
        return out


class Compiler:
    """Turns checked expressions into closures reading one Store; `active` maps an action's
    name to a one-element list holding whether it is active (the engine owns it)."""

    def __init__(self, store: Store, active: Dict[str, List[bool]]) -> None:
        self.store, self.active = store, active

    def compile(self, expr: ast.Expr) -> Compiled:
        """A condition: its value is always True, False or UNKNOWN."""
        ops: List[Any] = []
        inner = self._fn(expr, ops, None)
        cross = crossings(expr, lambda e: self._fn(e, [], None), self.store)
        if cross is not None:
            ops.append(cross)

            def fn() -> Any:
                value = as_bool(inner())
                cross.update()
                return value
            return Compiled(fn, ops)
        if _kleene(expr):
            return Compiled(inner, ops)  # already True, False or UNKNOWN: no as_bool call
        return Compiled(lambda: as_bool(inner()), ops)

    def _fn(self, e: ast.Expr, ops: List[Any], cell: Optional[List[Any]]) -> Fn:
        store = self.store
        if isinstance(e, ast.Lit):
            value = e.value
            return lambda: value
        if isinstance(e, ast.RuleRef):
            rules, key = store.rules, e.key
            return lambda: rules.get(key, UNKNOWN)
        if isinstance(e, ast.TopicRef):
            cell = store.cell((e.topic, e.path))
            return lambda: cell[0]
        if isinstance(e, ast.Unary):
            inner, op1 = self._fn(e.operand, ops, cell), UNARY[e.op]
            return lambda: op1(inner())
        if isinstance(e, ast.Binary) and e.op in ("and", "or") and isinstance(e.left, ast.Binary) \
                and e.left.op == e.op:
            parts = ast.chain(e, e.op)
            n_ops = len(ops)
            terms = tuple(self._fn(t, ops, cell) for t in parts)
            if len(ops) == n_ops:  # no operator in any term: the first decisive one ends it
                return _decided_chain(e.op, terms, parts, store)
            join = k_and if e.op == "and" else k_or

            def chain() -> Any:  # every term, always: their operators see every evaluation
                acc = as_bool(terms[0]())
                for t in terms[1:]:
                    acc = join(acc, as_bool(t()))
                return acc
            return chain
        if isinstance(e, ast.Binary):
            left, right, op2 = self._fn(e.left, ops, cell), self._fn(e.right, ops, cell), BINARY[e.op]
            fast = _compare_with_constant(e, left, right)
            if fast is not None:
                return fast
            return lambda: op2(left(), right())  # both sides always: their operators see every evaluation
        if isinstance(e, (ast.For, ast.Within)):
            operand = self._fn(e.operand, ops, cell)
            assert isinstance(e.duration, ast.Lit) and isinstance(e.duration.value, float)
            op = ForOp(e.duration.value) if isinstance(e, ast.For) else WithinOp(e.duration.value)
            ops.append(op)
            if _kleene(e.operand):
                return lambda: op.update(store.now, operand())
            return lambda: op.update(store.now, as_bool(operand()))
        if isinstance(e, ast.Latch):
            set_, reset = self._fn(e.set, ops, cell), self._fn(e.reset, ops, cell)
            latch = LatchOp()
            ops.append(latch)
            return lambda: latch.update(store.now, as_bool(set_()), as_bool(reset()))
        if isinstance(e, ast.Call):
            args: Tuple[Fn, ...] = tuple(self._fn(a, ops, cell) for a in e.args)
            fn = scalar_fn(e.func)
            if len(args) == 1:
                (a,) = args
                if e.func == "abs":
                    def absolute() -> Any:  # scalar_fn("abs") in one closure
                        v = a()
                        return abs(v) if type(v) is float and v == v else UNKNOWN
                    return absolute
                return lambda: fn(a())
            if len(args) == 2:
                a, b = args
                return lambda: fn(a(), b())
            return lambda: fn(*[a() for a in args])
        return self._builtin(e, ops, cell)

    def _builtin(self, e: ast.Expr, ops: List[Any], cell: Optional[List[Any]]) -> Fn:
        store = self.store
        if isinstance(e, ast.Age):
            topic = e.topic
            return lambda: store.age(topic)
        if isinstance(e, ast.StampAge):
            topic = e.topic
            return lambda: store.stamp_age(topic)
        if isinstance(e, ast.Frequency):
            topic, window = e.topic, e.window
            return lambda: store.frequency(topic, window)
        if isinstance(e, ast.NodeStat):
            node, attr = e.node, e.attr
            return lambda: store.node_value(node, attr)
        if isinstance(e, ast.Rate):
            rates, slot = store.rates, (e.ref.topic, e.ref.path)
            return lambda: rates.get(slot, UNKNOWN)
        if isinstance(e, ast.ArrayFn):
            read = self._fn(e.ref, ops, cell)
            limits = None
            if e.ref.path[:1] == ("ranges",) and len(e.ref.path) <= 2 and not e.elem:
                laser, topic = store.laser_limits, e.ref.topic
                limits = lambda: laser.get(topic)  # noqa: E731
            return _kept(array_fn(e.func, read, e.elem, limits), read, limits)
        if isinstance(e, ast.Quant):
            slot: List[Any] = [None]
            body = self._fn(e.body, ops, slot)
            return quantifier(e.func, self._fn(e.ref, ops, cell), slot, body)
        if isinstance(e, ast.Elem):
            assert cell is not None, "an element outside its quantifier"
            path = e.path
            return lambda: element(cell[0], path)
        if isinstance(e, ast.Active):
            flag = self.active.setdefault(e.action, [False])
            return lambda: flag[0]
        if isinstance(e, ast.Zone):
            x, y, poly = self._fn(e.x, ops, cell), self._fn(e.y, ops, cell), e.polygon
            measure = inside if e.func == "inside" else boundary_distance

            def zone() -> Any:
                px, py = as_num(x()), as_num(y())
                if px is UNKNOWN or py is UNKNOWN:
                    return UNKNOWN
                if math.isinf(px) or math.isinf(py):  # infinitely far: outside, at infinite distance
                    return False if measure is inside else math.inf
                return float(measure(px, py, poly)) if measure is boundary_distance else measure(px, py, poly)
            return zone
        raise TypeError(f"cannot evaluate {type(e).__name__}")


def _kept(fn: Fn, read: Fn, limits: Optional[Fn]) -> Fn:
    """min/max/len of an array term, kept with the array it was computed from: the array is
    immutable (a tuple or bytes that each message replaces), so evaluating the term again
    before its topic's next message (another topic's message, a deadline) costs no pass over it."""
    last: List[Any] = [None, None, None]  # the array, the laser limits, the value

    def apply() -> Any:
        arr, lim = read(), (limits() if limits is not None else None)
        if arr is last[0] and lim == last[1] and arr is not None:
            return last[2]
        value = fn()
        last[0], last[1], last[2] = arr, lim, value
        return value
    return apply


def _decided_chain(op: str, terms: Tuple[Fn, ...], parts: Sequence[ast.Expr], store: Store) -> Fn:
    """A Kleene `and`/`or` of stateless terms, short-circuited: `or` is true at the first true
    term, `and` false at the first false one; else unknown if any term is not a boolean.
    A chain of rule names (a behaviour over many rules) reads the rules' values directly."""
    decisive, neutral = (True, False) if op == "or" else (False, True)
    if all(isinstance(t, ast.RuleRef) for t in parts):
        get, keys = store.rules.get, tuple(t.key for t in parts)  # type: ignore[attr-defined]

        def rules() -> Any:
            unknown = False
            for v in map(get, keys):
                if v is decisive:
                    return decisive
                if v is not neutral:
                    unknown = True  # unknown, or not evaluated yet (None)
            return UNKNOWN if unknown else neutral
        return rules

    def chain() -> Any:
        unknown = False
        for t in terms:
            v = t()
            if v is decisive:
                return decisive
            if v is not neutral:
                unknown = True
        return UNKNOWN if unknown else neutral
    return chain


_KLEENE_OPS = frozenset(("<", "<=", ">", ">=", "==", "!=", "and", "or"))


def _kleene(e: ast.Expr) -> bool:
    """Whether e's closure only ever returns True, False or UNKNOWN (so as_bool would change nothing)."""
    if isinstance(e, ast.Binary):
        return e.op in _KLEENE_OPS
    if isinstance(e, ast.Unary):
        return e.op == "not"
    return isinstance(e, (ast.RuleRef, ast.For, ast.Within, ast.Latch))


_COMPARE = {"<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge}
_MIRROR = {"<": ">", "<=": ">=", ">": "<", ">=": "<="}  # c < x is x > c


def _compare_with_constant(e: ast.Binary, left: Fn, right: Fn) -> Optional[Fn]:
    """`x > 0.5` and the like, with a number on one side: the same value as BINARY's
    comparison (unknown unless x is a float that is not NaN), in one closure and one C call."""
    if e.op not in _COMPARE:
        return None
    if isinstance(e.right, ast.Lit) and type(e.right.value) is float and e.right.value == e.right.value:
        x, const, cmp = left, e.right.value, _COMPARE[e.op]
    elif isinstance(e.left, ast.Lit) and type(e.left.value) is float and e.left.value == e.left.value:
        x, const, cmp = right, e.left.value, _COMPARE[_MIRROR[e.op]]
    else:
        return None

    def compare() -> Any:
        v = x()
        if type(v) is float and v == v:
            return cmp(v, const)
        return UNKNOWN
    return compare
