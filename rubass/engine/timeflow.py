"""Exact instants at which an expression of time changes by itself (LANGUAGE.md §6, §11).

Between inputs, only `age` and `stamp_age` change, each at one second per second, and
`frequency` steps when a message leaves its window. So every number built from them is known
with its first two time derivatives: each such expression gets a second closure returning
(value, d/d now, d2/d now2). A comparison whose sides depend on time, and each min/max/abs/sqrt
kink inside them, announce the instant their difference reaches zero. For sums, differences,
scalar multiples, min, max and abs of ages this instant is exact, and so it is for a product of
two times (a quadratic). For quotients, sqrt and hypot it is the earlier of the first- and
second-order steps from the side that is not yet crossed, taken again at each evaluation (the
first-order step is early on a concave curve, the second-order one on a convex one; at a point
where the slope is infinite, as sqrt at 0, the next look is 1 ms later). Time inside a
quantifier's body or a zone's point is not followed here: the engine's ticks evaluate it.
"""
from __future__ import annotations

import math
from typing import Any, Callable, List, Optional, Tuple

from ..lang import ast
from .store import Store
from .values import UNKNOWN

Dual = Callable[[], Tuple[Any, float, float]]  # (value, slope, curvature) at the store's now

# Instants are set this much after the exact crossing, so that the evaluation there sees the new
# value despite float rounding (ROS wall-clock times near 1.7e9 s have a resolution of 2.4e-7 s).
CROSSING_MARGIN = 1e-6
# Where a difference's slope is infinite (sqrt at 0), it is looked at again this much later.
SINGULAR_STEP = 1e-3

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

    def __init__(self, diffs: List[Tuple[Dual, bool]], windows: List[Tuple[str, float]], store: Store) -> None:
        self.diffs, self.windows, self.store = diffs, windows, store
        self.due: Optional[float] = None
        self.at = float("-inf")

    def update(self) -> None:
        now = self.at = self.store.now
        best = math.inf
        for diff, exact in self.diffs:
            value, slope, curve = diff()
            if value is UNKNOWN:
                continue
            h = step_to_zero(value, slope, curve, exact)
            if h is not None:
                best = min(best, now + max(h, 0.0) + CROSSING_MARGIN)
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


def step_to_zero(value: float, slope: float, curve: float, exact: bool = False) -> Optional[float]:
    """How long until a difference of (value, slope, curvature) reaches zero: its first root ahead
    when it is `exact`ly a quadratic (or linear) in time, else the earlier of its first- and
    second-order approximations; None if none reaches it. A root up to CROSSING_MARGIN in the
    past counts (it is being crossed now)."""
    if curve == 0.0 and math.isfinite(slope):  # sums and scalings of ages: exact, and the common case
        if not slope:
            return None
        h = -value / slope
        return h if h >= -CROSSING_MARGIN else None
    if not math.isfinite(slope) or not math.isfinite(curve):
        toward = (slope > 0) != (value > 0) if slope and not math.isnan(slope) else True
        return SINGULAR_STEP if value != 0.0 and math.isfinite(value) and toward else None
    steps = []
    if slope and not exact:
        steps.append(-value / slope)
    disc = slope * slope - 2.0 * curve * value
    if -1e-9 * slope * slope <= disc < 0.0:
        disc = 0.0  # a double root, rounded below zero (sqrt((age - 3 s) * (age - 3 s)))
    if disc >= 0.0:
        root = math.sqrt(disc)
        steps += [(-slope - root) / curve, (-slope + root) / curve]
    ahead = [h for h in steps if h >= -CROSSING_MARGIN]
    return min(ahead) if ahead else None


def crossings(expr: ast.Expr, value_of: Callable[[ast.Expr], Callable[[], Any]], store: Store) -> Optional[Crossings]:
    """The Crossings of one rule or behaviour expression, or None when nothing in it changes
    with time alone. `value_of` compiles a sub-expression (the engine's own closures)."""
    duals = _Duals(value_of, store)
    diffs: List[Tuple[Dual, bool]] = []
    windows: List[Tuple[str, float]] = []
    stack = [expr]
    while stack:
        e = stack.pop()
        if isinstance(e, ast.Quant):
            continue
        if isinstance(e, ast.Frequency):
            windows.append((e.topic, e.window))
        if isinstance(e, ast.Binary) and e.op in _COMPARE and (time_dependent(e.left) or time_dependent(e.right)):
            diffs.append((duals.difference(e.left, e.right), _exact(e.left, e.right)))
        elif isinstance(e, ast.Binary) and e.op == "/" and time_dependent(e.right):
            # where the divisor is 0 the quotient is unknown (`1 s / age(…)` as a message arrives):
            # looked at again just past that instant, so its own crossing is planned from there
            diffs.append((duals.dual(e.right), _exact(e.right)))
        elif isinstance(e, ast.Call) and time_dependent(e):
            args = e.args
            if e.func in ("min", "max"):
                diffs += [(duals.difference(a, b), _exact(a, b)) for i, a in enumerate(args) for b in args[i + 1:]
                          if time_dependent(a) or time_dependent(b)]
            elif e.func in ("abs", "sqrt"):
                diffs.append((duals.dual(args[0]), _exact(args[0])))
            elif e.func == "hypot":  # a kink where its arguments are all 0: looked at where each is
                diffs += [(duals.dual(a), _exact(a)) for a in args if time_dependent(a)]
        stack.extend(ast.children(e))
    if not diffs and not windows:
        return None
    return Crossings(diffs, windows, store)


def _exact(*sides: ast.Expr) -> bool:
    """Whether numbers are, between inputs, polynomials of degree <= 2 in time (piecewise, at the
    kinks of abs/min/max, which are crossings of their own): then the quadratic step is exact."""
    degrees = [_degree(e) for e in sides]
    return all(d is not None and d <= 2 for d in degrees)


def _degree(e: ast.Expr) -> Optional[int]:
    """The degree in time of a number between inputs, None when it is not a polynomial."""
    if not time_dependent(e):
        return 0
    if isinstance(e, (ast.Age, ast.StampAge)):
        return 1
    if isinstance(e, ast.Unary) and e.op == "-":
        return _degree(e.operand)
    if isinstance(e, ast.Binary) and e.op in "+-*/":
        left, right = _degree(e.left), _degree(e.right)
        if left is None or right is None:
            return None
        if e.op == "*":
            return left + right
        if e.op == "/":
            return left if right == 0 else None
        return max(left, right)
    if isinstance(e, ast.Call) and e.func in ("abs", "min", "max"):
        degrees = [_degree(a) for a in e.args]
        return None if any(d is None for d in degrees) else max(degrees)
    return None


class _Duals:
    """Compiles numbers into (value, slope, curvature) closures."""

    def __init__(self, value_of: Callable[[ast.Expr], Callable[[], Any]], store: Store) -> None:
        self.value_of, self.store = value_of, store

    def difference(self, a: ast.Expr, b: ast.Expr) -> Dual:
        da, db = self.dual(a), self.dual(b)

        def diff() -> Tuple[Any, float, float]:
            (va, sa, ca), (vb, sb, cb) = da(), db()
            if type(va) is not float or type(vb) is not float:
                return UNKNOWN, 0.0, 0.0
            return va - vb, sa - sb, ca - cb
        return diff

    def dual(self, e: ast.Expr) -> Dual:
        if not time_dependent(e):
            fn = self.value_of(e)
            return lambda: (fn(), 0.0, 0.0)
        if isinstance(e, (ast.Age, ast.StampAge)):
            fn = self.value_of(e)
            return lambda: (fn(), 1.0, 0.0)
        if isinstance(e, ast.Unary) and e.op == "-":
            inner = self.dual(e.operand)

            def neg() -> Tuple[Any, float, float]:
                v, s, c = inner()
                return (-v if type(v) is float else UNKNOWN), -s, -c
            return neg
        if isinstance(e, ast.Binary) and e.op in "+-*/":
            return self._arith(e.op, self.dual(e.left), self.dual(e.right))
        if isinstance(e, ast.Call):
            return self._call(e.func, [self.dual(a) for a in e.args])
        fn = self.value_of(e)
        return lambda: (fn(), 0.0, 0.0)

    @staticmethod
    def _arith(op: str, da: Dual, db: Dual) -> Dual:
        def apply() -> Tuple[Any, float, float]:
            (a, sa, ca), (b, sb, cb) = da(), db()
            if type(a) is not float or type(b) is not float:
                return UNKNOWN, 0.0, 0.0
            if op == "+":
                return a + b, sa + sb, ca + cb
            if op == "-":
                return a - b, sa - sb, ca - cb
            if op == "*":
                return a * b, a * sb + b * sa, ca * b + 2.0 * sa * sb + a * cb
            if b == 0:
                return UNKNOWN, 0.0, 0.0
            q = a / b
            sq = (sa - q * sb) / b
            return q, sq, (ca - 2.0 * sq * sb - q * cb) / b
        return apply

    @staticmethod
    def _call(func: str, args: List[Dual]) -> Dual:
        def apply() -> Tuple[Any, float, float]:
            vals = [a() for a in args]
            if any(type(v[0]) is not float for v in vals):
                return UNKNOWN, 0.0, 0.0
            if func in ("min", "max"):
                pick = (min if func == "min" else max)(vals, key=lambda p: p[0])
                return pick
            (v, s, c) = vals[0]
            if func == "abs":
                sign = 1.0 if v > 0 or (v == 0 and (s > 0 or (s == 0 and c >= 0))) else -1.0
                return abs(v), sign * s, sign * c
            if func == "sqrt":
                return _sqrt(v, s, c)
            if func == "hypot":
                (w, t, d) = vals[1]
                return _sqrt(v * v + w * w, 2.0 * (v * s + w * t), 2.0 * (s * s + v * c + t * t + w * d))
            return UNKNOWN, 0.0, 0.0
        return apply


def _sqrt(u: float, s: float, c: float) -> Tuple[Any, float, float]:
    """sqrt of a number of (value, slope, curvature); slope infinite where u is 0 and moving."""
    if u < 0:
        return UNKNOWN, 0.0, 0.0
    root = math.sqrt(u)
    if root == 0.0:  # u ~ s h + c h^2 / 2 near here
        if s:
            return 0.0, math.copysign(math.inf, s), 0.0
        return 0.0, math.sqrt(max(c, 0.0) / 2.0), 0.0
    slope = s / (2.0 * root)
    return root, slope, (c - 2.0 * slope * slope) / (2.0 * root)
