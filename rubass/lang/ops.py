"""The one operator table: what +, <, and, abs(), sqrt() … mean, for constant folding in the
checker and for evaluation in the engine alike (LANGUAGE.md §5).

Every operation takes values that may be UNKNOWN and returns a value or UNKNOWN: any arithmetic
or comparison with unknown is unknown, NaN and division by zero are unknown, and/or/not are
Kleene's.
"""
from __future__ import annotations

import math
from typing import Any, Callable, Dict

from .values import UNKNOWN, as_bool, as_num, k_and, k_not, k_or


def _num2(op: Callable[[float, float], Any]) -> Callable[[Any, Any], Any]:
    def apply(a: Any, b: Any) -> Any:
        a, b = as_num(a), as_num(b)
        if a is UNKNOWN or b is UNKNOWN:
            return UNKNOWN
        try:
            r = op(a, b)
        except (ZeroDivisionError, OverflowError):
            return UNKNOWN
        return UNKNOWN if r != r else r  # NaN (inf - inf, 0 * inf) is unknown
    return apply


def equal(a: Any, b: Any) -> Any:
    if a is UNKNOWN or b is UNKNOWN or type(a) is not type(b):
        return UNKNOWN
    if type(a) is float and (a != a or b != b):
        return UNKNOWN
    return a == b


BINARY: Dict[str, Callable[[Any, Any], Any]] = {
    "+": _num2(lambda a, b: a + b), "-": _num2(lambda a, b: a - b),
    "*": _num2(lambda a, b: a * b), "/": _num2(lambda a, b: a / b),
    "<": _num2(lambda a, b: a < b), "<=": _num2(lambda a, b: a <= b),
    ">": _num2(lambda a, b: a > b), ">=": _num2(lambda a, b: a >= b),
    "==": equal, "!=": lambda a, b: k_not(equal(a, b)),
    "and": lambda a, b: k_and(as_bool(a), as_bool(b)), "or": lambda a, b: k_or(as_bool(a), as_bool(b)),
}

_neg = _num2(lambda a, b: a - b)

UNARY: Dict[str, Callable[[Any], Any]] = {
    "not": lambda a: k_not(as_bool(a)),
    "-": lambda a: _neg(0.0, a),
}


def _sqrt(x: float) -> Any:
    return math.sqrt(x) if x >= 0 else UNKNOWN


_SCALAR: Dict[str, Callable[..., Any]] = {
    "abs": abs, "sqrt": _sqrt, "hypot": math.hypot, "min": min, "max": max,
}


def scalar_fn(name: str) -> Callable[..., Any]:
    """abs, sqrt, hypot, min, max over numbers: unknown if any argument is (whatever its place)."""
    fn = _SCALAR[name]

    def apply(*args: Any) -> Any:
        nums = [as_num(a) for a in args]
        if any(n is UNKNOWN for n in nums):
            return UNKNOWN
        r = fn(*nums)
        return UNKNOWN if r is UNKNOWN or r != r else float(r)
    return apply


SCALAR_FUNCTIONS = frozenset(_SCALAR)
