"""Arrays (LANGUAGE.md §12): min/max/len over an array term, and the any/all/count quantifiers.

The store holds an array term's elements as the message gave them (a tuple, bytes for uint8[]);
the element path is read here, per evaluation, only for the terms the spec names.
"""
from __future__ import annotations

import math
from typing import Any, Callable, List, Optional, Tuple

from ..lang.ast import PathElem
from .fields import FieldError, convert, extract
from .values import UNKNOWN, as_bool, k_and, k_or

Fn = Callable[[], Any]


def element(item: Any, path: Tuple[PathElem, ...]) -> Any:
    """One element's value at `path` (UNKNOWN when it cannot be read as a value)."""
    try:
        return extract(item, path) if path else convert(item)
    except FieldError:
        return UNKNOWN


def _numbers(arr: Any, path: Tuple[PathElem, ...]) -> Optional[List[float]]:
    """The array's numeric values (per element `path`), NaN and non-numbers skipped (REP 117)."""
    if path:
        vals = [element(item, path) for item in arr]
        return [v for v in vals if type(v) is float and v == v]
    if isinstance(arr, bytes):
        return [float(b) for b in arr]
    return [float(v) for v in arr if (type(v) is float or type(v) is int) and v == v]


def array_fn(name: str, read: Fn, path: Tuple[PathElem, ...], limits: Optional[Fn] = None) -> Fn:
    """min/max/len of an array term; `limits` gives a LaserScan's (range_min, range_max) (§12)."""
    def apply() -> Any:
        arr = read()
        if not isinstance(arr, (tuple, bytes)):
            return UNKNOWN
        if name == "len":
            return float(len(arr))
        pick = min if name == "min" else max
        if limits is not None:
            lim = limits()
            if lim is not None:
                return _laser(pick, arr, lim)
        if not path and arr and type(arr[0]) is float:  # a typed float array: C speed when no NaN
            try:
                total = sum(arr)
            except TypeError:
                total = math.nan
            if total == total:
                return float(pick(arr))
        valid = _numbers(arr, path)
        return float(pick(valid)) if valid else UNKNOWN
    return apply


def _laser(pick: Callable[..., float], ranges: Any, lim: Tuple[float, float]) -> Any:
    """REP 117: NaN, +inf and finite readings outside [range_min, range_max] are no reading;
    -inf (too close to measure) is 0 m; unknown when no reading is left."""
    lo, hi = lim
    if not isinstance(ranges, tuple):
        return UNKNOWN
    if ranges:
        # C speed for the usual scan. min/max skip a NaN unless it comes first (then they return
        # it, and it fails the test below); so an extreme within the limits is the answer.
        best = pick(ranges)
        if lo <= best <= hi:
            return float(best)
    # With NaN, iterate in C still: the least reading >= range_min (NaN, -inf fail the test) is the
    # answer when it is <= range_max (+inf and the readings above are never the least of those);
    # for max the other way round.
    if pick is min:
        best = min(filter(lo.__le__, ranges), default=None)
        best = best if best is not None and best <= hi else None
    else:
        best = max(filter(hi.__ge__, ranges), default=None)
        best = best if best is not None and best >= lo else None
    if -math.inf in ranges:  # too close to measure: 0 m
        best = 0.0 if best is None else pick(best, 0.0)
    return UNKNOWN if best is None else float(best)


def quantifier(name: str, read: Fn, cell: List[Any], body: Fn) -> Fn:
    """any/all/count(body) with cell[0] set to each element in turn (Kleene or / and / count)."""
    def apply() -> Any:
        arr = read()
        if not isinstance(arr, (tuple, bytes)):
            return UNKNOWN
        if name == "count":
            n = 0.0
            for item in arr:
                cell[0] = item
                v = as_bool(body())
                if v is UNKNOWN:
                    return UNKNOWN
                n += v is True
            return n
        acc: Any = name == "all"
        join = k_and if name == "all" else k_or
        for item in arr:
            cell[0] = item
            acc = join(acc, as_bool(body()))
            if acc is (name == "any"):  # decided: one true for any, one false for all
                return acc
        return acc
    return apply
