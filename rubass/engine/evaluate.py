"""Evaluating checked expressions: each AST node becomes a small Python closure once, when
the engine is built, so a message costs only calls, never a tree walk or an `eval`."""
from __future__ import annotations

import math
from typing import Any, Callable, Dict, List, Tuple

from ..lang import ast
from .store import Store
from .temporal import ForTimer
from .values import UNKNOWN, as_bool, as_num, k_and, k_not, k_or

Fn = Callable[[], Any]


# Deadlines for age and frequency are set this much after the exact crossing, so that the
# evaluation there sees the new value despite float rounding (ROS wall-clock times near
# 1.7e9 s have a resolution of 2.4e-7 s).
CROSSING_MARGIN = 1e-6


class Compiled:
    """A compiled condition: its function, its `for` timers, and the age/frequency uses
    whose values change by themselves with time (so that they get deadlines too)."""

    def __init__(self, fn: Fn, timers: List[ForTimer], ages: List[Tuple[str, float]],
                 freqs: List[Tuple[str, float]]) -> None:
        self.fn, self.timers, self.ages, self.freqs = fn, timers, ages, freqs
        self.timed = bool(ages or freqs)

    def time_deadlines(self, store: Store, strict: bool = True) -> List[float]:
        """The instants after now (or at now, if not strict) at which an age crosses its
        limit or a frequency window loses a message. (`for` timers announce their own.)"""
        now = store.now

        def ahead(t: float) -> bool:
            return t > now if strict else t >= now

        out: List[float] = []
        for topic, limit in self.ages:
            base = store.last_arrival.get(topic, store.watch_start.get(topic))
            if base is not None and ahead(base + limit + CROSSING_MARGIN):
                out.append(base + limit + CROSSING_MARGIN)
        for topic, window in self.freqs:
            change = store.next_frequency_change(topic, window)
            if change is not None and ahead(change + CROSSING_MARGIN):
                out.append(change + CROSSING_MARGIN)
        return out


def _num2(op: Callable[[float, float], Any]) -> Callable[[Any, Any], Any]:
    def apply(a: Any, b: Any) -> Any:
        a, b = as_num(a), as_num(b)
        if a is UNKNOWN or b is UNKNOWN:
            return UNKNOWN
        try:
            r = op(a, b)
        except ZeroDivisionError:
            return UNKNOWN
        return UNKNOWN if isinstance(r, float) and math.isnan(r) else r
    return apply


def _equal(a: Any, b: Any) -> Any:
    if a is UNKNOWN or b is UNKNOWN or (type(a) is not type(b)):
        return UNKNOWN
    return a == b


_BINARY: Dict[str, Callable[[Any, Any], Any]] = {
    "+": _num2(lambda a, b: a + b), "-": _num2(lambda a, b: a - b),
    "*": _num2(lambda a, b: a * b), "/": _num2(lambda a, b: a / b),
    "<": _num2(lambda a, b: a < b), "<=": _num2(lambda a, b: a <= b),
    ">": _num2(lambda a, b: a > b), ">=": _num2(lambda a, b: a >= b),
    "==": _equal, "!=": lambda a, b: k_not(_equal(a, b)),
    "and": lambda a, b: k_and(as_bool(a), as_bool(b)), "or": lambda a, b: k_or(as_bool(a), as_bool(b)),
}


def _scalar_fn(name: str) -> Callable[..., Any]:
    def apply(*args: Any) -> Any:
        nums = [as_num(a) for a in args]
        if any(n is UNKNOWN for n in nums):
            return UNKNOWN
        if name == "abs":
            return abs(nums[0])
        if name == "sqrt":
            return math.sqrt(nums[0]) if nums[0] >= 0 else UNKNOWN
        if name == "hypot":
            return math.hypot(nums[0], nums[1])
        return min(nums) if name == "min" else max(nums)
    return apply


def _array_fn(name: str, read: Fn) -> Fn:
    def apply() -> Any:
        arr = read()
        if not isinstance(arr, (tuple, bytes)):
            return UNKNOWN
        if name == "len":
            return float(len(arr))
        if isinstance(arr, bytes):
            return UNKNOWN if not arr else float(min(arr) if name == "min" else max(arr))
        if arr and type(arr[0]) is float:  # a typed float array: C-speed when it holds no NaN
            try:
                total = sum(arr)
            except TypeError:
                total = math.nan
            if total == total:  # NaN when an element is NaN (or holds both inf and -inf): filter below
                return float(min(arr) if name == "min" else max(arr))
        # numbers only, NaN (v != v) and unknown elements skipped; bool is not a number here
        valid = [v for v in arr if (type(v) is float or type(v) is int) and v == v]
        if not valid:
            return UNKNOWN
        return float(min(valid) if name == "min" else max(valid))
    return apply


class Compiler:
    """Turns checked expressions into closures reading one Store."""

    def __init__(self, store: Store) -> None:
        self.store = store

    def compile(self, expr: ast.Expr) -> Compiled:
        """A condition: its value is always True, False or UNKNOWN."""
        timers: List[ForTimer] = []
        inner = self._fn(expr, timers)
        ages: List[Tuple[str, float]] = []
        freqs: List[Tuple[str, float]] = []
        for e in ast.walk(expr):
            if isinstance(e, ast.Call) and e.func == "frequency":
                window = e.args[1].value if len(e.args) > 1 else 1.0  # type: ignore[union-attr]
                freqs.append((e.args[0].topic, float(window)))  # type: ignore[union-attr,arg-type]
            if isinstance(e, ast.Binary) and e.op in ("<", "<=", ">", ">="):
                for a, b in ((e.left, e.right), (e.right, e.left)):
                    if isinstance(a, ast.Call) and a.func == "age" and isinstance(b, ast.Lit) \
                            and isinstance(b.value, float):
                        ages.append((a.args[0].topic, b.value))  # type: ignore[union-attr]
        return Compiled(lambda: as_bool(inner()), timers, ages, freqs)

    def _fn(self, e: ast.Expr, timers: List[ForTimer]) -> Fn:
        store = self.store
        if isinstance(e, ast.Lit):
            value = e.value
            return lambda: value
        if isinstance(e, ast.RuleRef):
            rules, key = store.rules, e.key
            return lambda: rules.get(key, UNKNOWN)
        if isinstance(e, ast.TopicRef):
            fields, slot = store.fields, (e.topic, e.path)
            return lambda: fields.get(slot, UNKNOWN)
        if isinstance(e, ast.Unary):
            inner = self._fn(e.operand, timers)
            if e.op == "not":
                return lambda: k_not(as_bool(inner()))
            neg = _num2(lambda a, b: a - b)
            return lambda: neg(0.0, inner())
        if isinstance(e, ast.Binary):
            left, right, op = self._fn(e.left, timers), self._fn(e.right, timers), _BINARY[e.op]
            return lambda: op(left(), right())  # both sides always: their timers must see every evaluation
        if isinstance(e, ast.For):
            operand = self._fn(e.operand, timers)
            assert isinstance(e.duration, ast.Lit) and isinstance(e.duration.value, float)
            timer = ForTimer(e.duration.value)
            timers.append(timer)
            return lambda: timer.update(store.now, as_bool(operand()))
        if isinstance(e, ast.Call):
            return self._call(e, timers)
        raise TypeError(f"cannot evaluate {type(e).__name__}")

    def _call(self, e: ast.Call, timers: List[ForTimer]) -> Fn:
        store = self.store
        if e.func == "age":
            topic = e.args[0].topic  # type: ignore[union-attr]
            return lambda: store.age(topic)
        if e.func == "frequency":
            topic = e.args[0].topic  # type: ignore[union-attr]
            window = e.args[1].value if len(e.args) > 1 else 1.0  # type: ignore[union-attr]
            return lambda: store.frequency(topic, window)  # type: ignore[arg-type]
        if e.func in ("alive", "cpu", "memory"):
            node, attr = e.args[0].node, e.func  # type: ignore[union-attr]
            return lambda: store.node_value(node, attr)
        if e.func in ("min", "max", "len") and len(e.args) == 1:
            return _array_fn(e.func, self._fn(e.args[0], timers))
        args: Tuple[Fn, ...] = tuple(self._fn(a, timers) for a in e.args)
        fn = _scalar_fn(e.func)
        if len(args) == 1:
            (a,) = args
            return lambda: fn(a())
        if len(args) == 2:
            a, b = args
            return lambda: fn(a(), b())
        return lambda: fn(*[a() for a in args])
