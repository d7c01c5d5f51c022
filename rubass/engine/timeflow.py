"""Exact instants at which an expression of time changes by itself (LANGUAGE.md §6, §11).

Between inputs, only `age` and `stamp_age` change, each at one second per second, and
`frequency` steps when a message leaves its window. So every number built from them is known
with its slope: each such expression gets a second closure returning (value, d value / d now).
A comparison whose sides depend on time, and each min/max/abs/sqrt kink inside them, announce
the instant their difference reaches zero. For sums, differences, scalar multiples, min, max and
abs of ages this instant is exact; for products or quotients of two times, sqrt and hypot it is a
Newton step from the side that is not yet crossed, taken again at each evaluation. Time inside a
quantifier's body or a zone's point is not followed here: the engine's ticks evaluate it.
"""
from __future__ import annotations

import math
from typing import Any, Callable, List, Optional, Tuple

from ..lang import ast
from .store import Store
from .values import UNKNOWN

Dual = Callable[[], Tuple[Any, float]]

# Instants are set this much after the exact crossing, so that the evaluation there sees the new
# value despite float rounding (ROS wall-clock times near 1.7e9 s have a resolution of 2.4e-7 s).
CROSSING_MARGIN = 1e-6

_COMPARE = ("<", "<=", ">", ">=", "==", "!=")


def time_dependent(e: ast.Expr) -> bool:
    """Whether the value of a number changes with time alone (it contains age or stamp_age)."""
    if isinstance(e, ast.Quant):
        return False  # elements are read per evaluation: a quantifier's body is not followed in time
    return isinstance(e, (ast.Age, ast.StampAge)) or any(time_dependent(c) for c in ast.children(e))


class Crossings:
    """The zero crossings of a node's time-dependent differences; `deadline()` is the earliest
    still ahead, computed at each evaluation (`update`)."""

    __slots__ = ("diffs", "windows", "store", "due", "at")

    def __init__(self, diffs: List[Dual], windows: List[Tuple[str, float]], store: Store) -> None:
        self.diffs, self.windows, self.store = diffs, windows, store
        self.due: Optional[float] = None
        self.at = float("-inf")

    def update(self) -> None:
        now = self.at = self.store.now
        best = math.inf
        for diff in self.diffs:
            value, slope = diff()
            if value is UNKNOWN or not slope or not math.isfinite(slope):
                continue
            t = now - value / slope
            if t >= now - CROSSING_MARGIN:
                best = min(best, max(t, now) + CROSSING_MARGIN)
        for topic, window in self.windows:
            change = self.store.next_frequency_change(topic, window)
            if change is not None and change + CROSSING_MARGIN > now:
                best = min(best, change + CROSSING_MARGIN)
        self.due = best if best < math.inf else None

    def deadline(self) -> Optional[float]:
        return self.due if self.due is not None and self.due > self.at else None

    def reset(self) -> None:
        self.due = None

    def snapshot(self) -> Any:
        return None

    def restore(self, state: Any) -> None:
        pass


def crossings(expr: ast.Expr, value_of: Callable[[ast.Expr], Callable[[], Any]], store: Store) -> Optional[Crossings]:
    """The Crossings of one rule or behaviour expression, or None when nothing in it changes
    with time alone. `value_of` compiles a sub-expression (the engine's own closures)."""
    duals = _Duals(value_of, store)
    diffs: List[Dual] = []
    windows: List[Tuple[str, float]] = []
    stack = [expr]
    while stack:
        e = stack.pop()
        if isinstance(e, ast.Quant):
            continue
        if isinstance(e, ast.Frequency):
            windows.append((e.topic, e.window))
        if isinstance(e, ast.Binary) and e.op in _COMPARE and (time_dependent(e.left) or time_dependent(e.right)):
            diffs.append(duals.difference(e.left, e.right))
        elif isinstance(e, ast.Call) and time_dependent(e):
            args = e.args
            if e.func in ("min", "max"):
                diffs += [duals.difference(a, b) for i, a in enumerate(args) for b in args[i + 1:]
                          if time_dependent(a) or time_dependent(b)]
            elif e.func in ("abs", "sqrt"):
                diffs.append(duals.dual(args[0]))
        stack.extend(ast.children(e))
    if not diffs and not windows:
        return None
    return Crossings(diffs, windows, store)


class _Duals:
    """Compiles numbers into (value, slope) closures."""

    def __init__(self, value_of: Callable[[ast.Expr], Callable[[], Any]], store: Store) -> None:
        self.value_of, self.store = value_of, store

    def difference(self, a: ast.Expr, b: ast.Expr) -> Dual:
        da, db = self.dual(a), self.dual(b)

        def diff() -> Tuple[Any, float]:
            (va, sa), (vb, sb) = da(), db()
            if type(va) is not float or type(vb) is not float:
                return UNKNOWN, 0.0
            return va - vb, sa - sb
        return diff

    def dual(self, e: ast.Expr) -> Dual:
        if not time_dependent(e):
            fn = self.value_of(e)
            return lambda: (fn(), 0.0)
        if isinstance(e, (ast.Age, ast.StampAge)):
            fn = self.value_of(e)
            return lambda: (fn(), 1.0)
        if isinstance(e, ast.Unary) and e.op == "-":
            inner = self.dual(e.operand)

            def neg() -> Tuple[Any, float]:
                v, s = inner()
                return (-v if type(v) is float else UNKNOWN), -s
            return neg
        if isinstance(e, ast.Binary) and e.op in "+-*/":
            return self._arith(e.op, self.dual(e.left), self.dual(e.right))
        if isinstance(e, ast.Call):
            return self._call(e.func, [self.dual(a) for a in e.args])
        fn = self.value_of(e)
        return lambda: (fn(), 0.0)

    @staticmethod
    def _arith(op: str, da: Dual, db: Dual) -> Dual:
        def apply() -> Tuple[Any, float]:
            (a, sa), (b, sb) = da(), db()
            if type(a) is not float or type(b) is not float:
                return UNKNOWN, 0.0
            if op == "+":
                return a + b, sa + sb
            if op == "-":
                return a - b, sa - sb
            if op == "*":
                return a * b, a * sb + b * sa
            if b == 0:
                return UNKNOWN, 0.0
            return a / b, (sa * b - a * sb) / (b * b)
        return apply

    @staticmethod
    def _call(func: str, args: List[Dual]) -> Dual:
        def apply() -> Tuple[Any, float]:
            vals = [a() for a in args]
            if any(type(v) is not float for v, _ in vals):
                return UNKNOWN, 0.0
            if func in ("min", "max"):
                pick = (min if func == "min" else max)(vals, key=lambda p: p[0])
                return pick
            (v, s) = vals[0]
            if func == "abs":
                return abs(v), (s if v > 0 else -s if v < 0 else abs(s))
            if func == "sqrt":
                if v < 0:
                    return UNKNOWN, 0.0
                root = math.sqrt(v)
                return root, (s / (2 * root) if root > 0 else math.inf)
            if func == "hypot":
                (w, t) = vals[1]
                h = math.hypot(v, w)
                return h, ((v * s + w * t) / h if h > 0 else 0.0)
            return UNKNOWN, 0.0
        return apply
