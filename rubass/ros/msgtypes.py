"""Checking a spec's field paths against a ROS message class (genpy, static or dynamic)."""
from __future__ import annotations

import re
import sys
from typing import Any, Optional, Tuple

from ..lang.ast import PathElem, Slice
from ..lang.fielduse import CONDITION, NUMBER

_ARRAY = re.compile(r"(.*)\[(\d*)\]$")
_PRIMITIVES = {"bool", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64",
               "float32", "float64", "string", "time", "duration", "char", "byte"}


def _message_class(type_name: str, near: Any) -> Optional[Any]:
    """The class of a nested message type, looked up beside `near` (dynamic types) or installed."""
    if type_name == "Header":
        type_name = "std_msgs/Header"
    if "/" not in type_name:
        return None
    pkg, name = type_name.split("/", 1)
    found = getattr(sys.modules.get(near.__module__), f"_{pkg}__{name}", None)
    if found is not None:
        return found
    try:
        import genpy.message

        return genpy.message.get_message_class(type_name)
    except Exception:  # not installed here: the path cannot be checked further
        return None


def check_path(cls: Any, path: Tuple[PathElem, ...], scalar: bool = False, need: Optional[str] = None) -> Optional[str]:
    """None if `path` can exist in messages of class `cls`, else what is wrong with it.
    scalar: the spec uses the value as a number or truth value (not as min(), max(), len()'s argument);
    need: 'number' or 'condition' when the spec computes with it or needs it true or false (fielduse.py)."""
    type_name = getattr(cls, "_type", cls.__name__)
    current: Optional[Any] = cls
    slot_type = type_name
    done = ""
    for i, elem in enumerate(path):
        m = _ARRAY.match(slot_type)
        if isinstance(elem, (int, Slice)):
            if not m:
                return f"'{done or type_name}' is not an array (it is {slot_type})"
            if isinstance(elem, Slice) and i == len(path) - 1:
                return None  # an array term (§12): its elements are read by min/max/len or a quantifier
            slot_type = m.group(1)
            current = None if slot_type in _PRIMITIVES else _message_class(slot_type, cls)
            done += elem.text if isinstance(elem, Slice) else f"[{elem}]"
            continue
        if m:
            return f"'{done}' is an array ({slot_type}): index it, e.g. '{done}[0].{elem}'"
        if slot_type in _PRIMITIVES:
            return f"'{done}' is a {slot_type}, it has no field '{elem}'"
        if current is None:
            return None  # a type we cannot see into: accept
        slots = list(getattr(current, "__slots__", ()))
        if elem not in slots:
            where = f"'{done}' ({slot_type})" if done else type_name
            return f"{where} has no field '{elem}' (fields: {', '.join(slots)})"
        slot_type = current._slot_types[slots.index(elem)]
        done = f"{done}.{elem}" if done else elem
        am = _ARRAY.match(slot_type)
        base = am.group(1) if am else slot_type
        current = None if base in _PRIMITIVES else _message_class(base, cls)
    if not _ARRAY.match(slot_type) and slot_type not in _PRIMITIVES:
        return f"'{done}' is a message ({slot_type}), not a value: name one of its fields"
    if scalar and _ARRAY.match(slot_type):
        return (f"'{done}' is an array ({slot_type}) used as a single value: take min(), max() or len() of it, "
                f"or index it, e.g. '{done}[0]'")
    if need == NUMBER and slot_type in ("string", "bool"):
        return f"'{done}' is a {slot_type}, and the spec uses it as a number: its value would never be known"
    if need == CONDITION and slot_type in _PRIMITIVES and slot_type != "bool":
        example = f"{done} == \"…\"" if slot_type == "string" else f"{done} > 0"
        return (f"'{done}' is a {slot_type}, and the spec uses it as a condition (true or false): compare it, "
                f"e.g. '{example}'")
    return None
