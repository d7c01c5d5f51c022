"""Values and Kleene's three-valued logic (LANGUAGE.md §5), shared by the checker's folding and the engine."""
from __future__ import annotations

import math
from typing import Any, Tuple, Union


class _Unknown:
    """The one unknown value: missing data, NaN, something that cannot be measured."""

    _instance = None

    def __new__(cls) -> "_Unknown":
        if cls._instance is None:
            cls._instance = super().__new__(cls)
        return cls._instance

    def __repr__(self) -> str:
        return "unknown"

    def __bool__(self) -> bool:
        raise TypeError("unknown has no truth value: compare with `is True`")


UNKNOWN: Any = _Unknown()
Value = Union[float, bool, str, Tuple[Any, ...], _Unknown]


def k_and(a: Any, b: Any) -> Any:
    if a is False or b is False:
        return False
    if a is True and b is True:
        return True
    return UNKNOWN


def k_or(a: Any, b: Any) -> Any:
    if a is True or b is True:
        return True
    if a is False and b is False:
        return False
    return UNKNOWN


def k_not(a: Any) -> Any:
    if a is True:
        return False
    if a is False:
        return True
    return UNKNOWN


def as_bool(v: Any) -> Any:
    """A condition: True, False, or UNKNOWN for anything that is not a boolean."""
    return v if v is True or v is False else UNKNOWN


def as_num(v: Any) -> Any:
    """A number: a finite or infinite float, or UNKNOWN (NaN, booleans, strings, arrays)."""
    if type(v) is float:
        return UNKNOWN if math.isnan(v) else v
    return UNKNOWN
