"""Reading a field path out of a message of any type, without importing ROS.

Works on deserialised rospy messages (attributes), on dicts (tests, YAML traces) and on
anything shaped like them. Integers become floats, NaN and short arrays become UNKNOWN.
Numeric arrays are kept as they come (a tuple, or bytes for uint8[]), so a huge array costs
one copy, not one conversion per element; the array functions (min, max, len) skip NaN.
"""
from __future__ import annotations

import math
import operator
from typing import Any, Callable, Dict, Tuple

from ..lang.errors import RubassError
from ..lang.ast import PathElem, Slice, path_suffix
from .values import UNKNOWN


class FieldError(RubassError):
    """A field path that does not exist in the message's type (a spec/type mismatch)."""


def path_text(path: Tuple[PathElem, ...]) -> str:
    return path_suffix(path).lstrip(".")


# (message class, path of field names) -> a C attribute getter, once the path has been read from
# that class by the checked walk below: its nested classes are fixed, so the getter reads the same
_GETTERS: Dict[Tuple[type, Tuple[PathElem, ...]], Callable[[Any], Any]] = {}


def extract(msg: Any, path: Tuple[PathElem, ...], raw: bool = False) -> Any:
    """The value at `path` in `msg`; FieldError when the type has no such field.

    A path ending in a slice or `[*]` (an array term, §12) gives the tuple of its elements
    as they are (messages stay messages): the engine reads each element's field later.
    """
    getter = _GETTERS.get((type(msg), path))
    if getter is not None:
        try:
            value = getter(msg)
        except AttributeError:
            pass  # not shaped like the first message of its class: the checked walk says why
        else:
            return value if raw else convert(value, path)
    value, final = _walk(msg, path)
    if final:
        return value
    if type(msg) is not dict and all(type(e) is str for e in path):
        _GETTERS[(type(msg), path)] = operator.attrgetter(".".join(path))  # type: ignore[arg-type]
    return value if raw else convert(value, path)


def _walk(msg: Any, path: Tuple[PathElem, ...]) -> Tuple[Any, bool]:
    """extract's checked walk: (the raw value, whether it is final: an array term, a missing element)."""
    value = msg
    for i, elem in enumerate(path):
        if isinstance(elem, Slice):
            if not isinstance(value, (list, tuple, bytes, bytearray)):
                raise FieldError(f"'{path_text(path[:i])}' is not an array")
            part = value[elem.start:elem.stop]
            return (bytes(part) if isinstance(part, (bytes, bytearray)) else tuple(part)), True
        if isinstance(elem, int):
            if not isinstance(value, (list, tuple, bytes, bytearray)):
                raise FieldError(f"'{path_text(path[:i])}' is not an array")
            if not -len(value) <= elem < len(value):
                return UNKNOWN, True  # arrays vary in length: a missing element is missing data
            value = value[elem]
            continue
        if isinstance(value, dict):
            if elem not in value:
                raise FieldError(f"no field '{path_text(path[:i + 1])}'")
            value = value[elem]
            continue
        slots = getattr(value, "__slots__", None)
        if slots is not None and elem not in slots:
            raise FieldError(f"no field '{path_text(path[:i + 1])}'")
        try:
            value = getattr(value, elem)
        except AttributeError:
            raise FieldError(f"no field '{path_text(path[:i + 1])}'") from None
    return value, False


def _is_message(value: Any) -> bool:
    """A message (genpy, or a test's dict), not a time: its fields are read by name."""
    return isinstance(value, dict) or (hasattr(value, "__slots__") and not callable(getattr(value, "to_sec", None)))


def convert(value: Any, path: Tuple[PathElem, ...] = ()) -> Any:
    """A message value as an engine value."""
    if type(value) is float:  # the common case first
        return value if value == value else UNKNOWN
    if value is True or value is False:
        return value
    if isinstance(value, (int, float)):
        f = float(value)
        return UNKNOWN if math.isnan(f) else f
    if isinstance(value, str):
        return value
    if isinstance(value, bytes):
        return value  # uint8[] / char[]: kept as it is (a camera image is megabytes)
    if isinstance(value, bytearray):
        return bytes(value)
    if isinstance(value, (list, tuple)):
        if value and type(value[0]) in (float, int):  # a numeric array (ROS arrays are typed):
            return tuple(value)  # copied as it is; min/max skip its NaNs (no per-element work here)
        if value and _is_message(value[0]):  # an array of messages: its elements stay messages, as
            return tuple(value)  # `[*]` gives them (len() of it; a value is unknown, as any array's)
        return tuple(convert(v, path) for v in value)
    to_sec = getattr(value, "to_sec", None)  # rospy Time / Duration
    if callable(to_sec):
        return float(to_sec())
    raise FieldError(f"'{path_text(path)}' is a message ({type(value).__name__}), not a value: name one of its fields")
