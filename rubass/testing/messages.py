"""Real ROS message objects for test inputs, built from installed types (genpy), field by field.

Values are checked against the field's type as they are set: a field the type lacks, a string
for a number or a fraction for an integer is a MessageError saying which field and why.
"""
from __future__ import annotations

import importlib
import io
import math
import re
import sys
from typing import Any, Dict, List, Optional, Tuple

from ..lang.errors import RubassError, did_you_mean

_ARRAY = re.compile(r"(.*)\[(\d*)\]$")
_INTS = {"int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64", "char", "byte"}
_FLOATS = {"float32", "float64"}
_NON_FINITE = ("nan", "inf", "-inf", "+inf")
_PATH = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)|\[(-?\d+)\]|(\.)")

Path = Tuple[Any, ...]


class MessageError(RubassError, ValueError):
    """A type that is not installed, or a field or value the type does not allow."""


class NoRosPython(MessageError):
    """This interpreter cannot import ROS 1's Python message support (genpy, roslib): no type can be built."""


_DYNAMIC: Dict[str, Any] = {}  # classes built from system models, by type name


def _ros_python(type_name: str) -> None:
    """NoRosPython when genpy or roslib cannot be imported at all (the python3 first on PATH has no ROS):
    then no type is installed as far as this interpreter can tell, and saying so would mislead."""
    try:
        for module in ("genpy", "roslib.message"):
            importlib.import_module(module)
    except ImportError as exc:
        raise NoRosPython(f"message type {type_name} needs ROS 1's Python message support, which this interpreter "
                          f"({sys.executable}) cannot import ({exc}): run rubass with /usr/bin/python3") from None


def model_class(type_name: str, registry: Any) -> Any:
    """A class built from a system model's definitions (a type not installed here), or None."""
    specs = registry.closure([type_name]) if registry is not None else []
    if not specs or specs[0].type != type_name:
        return None
    sep = "\n" + "=" * 80 + "\n"
    text = specs[0].text() + "".join(f"{sep}MSG: {d.type}\n{d.text()}" for d in specs[1:])
    known = {d.type for d in specs}
    for dep in sorted({f.type for d in specs for f in d.fields if not f.is_primitive} - known):
        installed = _installed(dep)  # e.g. std_msgs/Header: the model holds only the robot's own types
        if installed is not None:
            text += f"{sep}MSG: {dep}\n{installed._full_text}"
    try:
        import genpy.dynamic

        classes = genpy.dynamic.generate_dynamic(type_name, text)
    except Exception as exc:  # genpy raises assorted errors for a definition it cannot build
        raise MessageError(f"message type {type_name}: the system model's definition cannot be built ({exc})") from None
    _DYNAMIC.update(classes)  # its nested types too, for arrays of them
    return classes[type_name]


def _installed(type_name: str) -> Any:
    try:
        import roslib.message

        return roslib.message.get_message_class(type_name)
    except Exception:  # roslib raises assorted errors for unknown packages
        return None


def message_class(type_name: Any, registry: Any = None) -> Any:
    """The installed class of `pkg/Name`, else one built from the system model's definition
    (`registry`: a rubass.lang.msgdef.Registry), or MessageError."""
    if not isinstance(type_name, str) or not re.fullmatch(r"[A-Za-z_][\w]*/[A-Za-z_]\w*", type_name):
        raise MessageError(f"'{type_name}' is not a message type (pkg/Name, e.g. nav_msgs/Odometry)")
    _ros_python(type_name)
    cls = _installed(type_name)
    if cls is None:
        cls = model_class(type_name, registry)
    if cls is None:
        raise MessageError(f"message type {type_name} is not installed here (is its Debian package installed?)"
                           + ("" if registry is None else " and the system model does not define it"))
    return cls


def parse_path(text: Any) -> Path:
    """'twist.twist.linear.x' or 'ranges[0]' -> ('twist', 'twist', 'linear', 'x') / ('ranges', 0)."""
    if not isinstance(text, str) or not text:
        raise MessageError("a field path is a string such as twist.twist.linear.x")
    out: List[Any] = []
    pos = 0
    for m in _PATH.finditer(text):
        if m.start() != pos:
            break
        pos = m.end()
        if m.group(1):
            out.append(m.group(1))
        elif m.group(2) is not None:
            out.append(int(m.group(2)))
    if pos != len(text) or not out or not isinstance(out[0], str):
        raise MessageError(f"'{text}' is not a field path (such as twist.twist.linear.x or ranges[0])")
    return tuple(out)


def _text(path: Path) -> str:
    return "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in path).lstrip(".")


def _slot_type(obj: Any, name: str, done: Path, within: str = "") -> str:
    """The type of field `name` of `obj` (reached by `done`, or written `within` in a mapping)."""
    slots = list(getattr(obj, "__slots__", ()))
    if name not in slots:
        where = f"'{within or _text(done)}' ({obj._type})" if done or within else obj._type
        raise MessageError(f"{where} has no field '{name}'{did_you_mean(name, slots)} (fields: {', '.join(slots)})")
    return obj._slot_types[slots.index(name)]


def _nested_class(type_name: str) -> Any:
    if type_name == "Header":
        type_name = "std_msgs/Header"
    return _DYNAMIC.get(type_name) or message_class(type_name)


def _int_range(slot: str) -> Tuple[int, int]:
    """The values an integer field holds: uint8 0 to 255, int8 -128 to 127 (byte is ROS 1's int8, char its
    uint8), as genpy packs them."""
    kind = {"byte": "int8", "char": "uint8"}.get(slot, slot)
    bits = int(kind.lstrip("uint"))
    return (0, 2 ** bits - 1) if kind.startswith("u") else (-2 ** (bits - 1), 2 ** (bits - 1) - 1)


def _a(slot: str) -> str:
    """'an int8', 'a float64', 'a uint8': the type with its article."""
    return f"{'an' if slot[:1] in 'aeio' else 'a'} {slot}"


def seconds(value: Any) -> Any:
    """A time written with a unit (`500 ms`, `"0.6 s"`, as series and `at` take them) as its number of
    seconds; any other value as it is (the setter says what is wrong with it)."""
    if isinstance(value, str):
        from ..lang.units import TIME, parse_quantity

        q = parse_quantity(value)
        if q is not None and (q[1] == TIME or (q[1] == () and re.fullmatch(r"\s*[-+.\d][\d.eE+-]*\s*", value))):
            return q[0]
    return value


def _scalar(slot: str, value: Any, where: str) -> Any:
    if slot in _FLOATS:
        if isinstance(value, str) and value.strip().lower() in _NON_FINITE:  # as in series (TESTING.md)
            return float(value.strip().lower())
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise MessageError(f"{where} is {_a(slot)}: {value!r} is not a number")
        return float(value)
    if slot in _INTS:
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        if isinstance(value, bool) or not isinstance(value, int):
            raise MessageError(f"{where} is {_a(slot)}: {value!r} is not an integer")
        low, high = _int_range(slot)
        if not low <= value <= high:
            raise MessageError(f"{where} is {_a(slot)}: {value} is out of range {low} to {high}")
        return value
    if slot == "bool":
        if value in (0, 1) and not isinstance(value, bool):
            value = bool(value)
        if not isinstance(value, bool):
            raise MessageError(f"{where} is a bool: {value!r} is not true or false")
        return value
    if slot == "string":
        if not isinstance(value, str):
            raise MessageError(f"{where} is a string: {value!r} is not a string (quote it)")
        return value
    if slot in ("time", "duration"):
        import genpy

        value = seconds(value)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise MessageError(f"{where} is {_a(slot)}: {value!r} is not a number of seconds (or a time "
                               f"such as 500 ms)")
        try:
            return (genpy.Time if slot == "time" else genpy.Duration).from_sec(float(value)) if value else \
                (genpy.Time() if slot == "time" else genpy.Duration())
        except (TypeError, ValueError, OverflowError) as exc:  # e.g. a negative time
            raise MessageError(f"{where} is {_a(slot)}: {value!r} cannot be one ({exc})") from None
    return None  # a message: handled by the caller


def convert(slot: str, value: Any, where: str, current: Any = None) -> Any:
    """`value` (from YAML) as a value of a field of type `slot`; dicts fill `current` in place."""
    m = _ARRAY.match(slot)
    if m:
        if not isinstance(value, (list, tuple)):
            raise MessageError(f"{where} is an array ({slot}): give a list")
        if m.group(2) and len(value) != int(m.group(2)):
            raise MessageError(f"{where} holds exactly {m.group(2)} elements, not {len(value)}")
        items = [convert(m.group(1), v, f"{where}[{i}]") for i, v in enumerate(value)]
        return bytes(items) if m.group(1) in ("uint8", "char") else items
    scalar = _scalar(slot, value, where)
    if scalar is not None:
        return scalar
    if not isinstance(value, dict):
        raise MessageError(f"{where} is a message ({slot}): give its fields as a mapping")
    obj = current if current is not None else _nested_class(slot)()
    for k, v in value.items():
        setattr(obj, str(k), convert(_slot_type(obj, str(k), (), where), v, f"{where}.{k}", getattr(obj, str(k), None)
                                     if str(k) in obj.__slots__ else None))
    return obj


def assign(msg: Any, path: Path, value: Any) -> None:
    """Set the field at `path` of `msg` (fields on the way must exist; array elements must exist)."""
    obj: Any = msg
    done: Path = ()
    for i, elem in enumerate(path):
        last = i == len(path) - 1
        if isinstance(elem, int):
            if not isinstance(obj, list) or not -len(obj) <= elem < len(obj):
                raise MessageError(f"'{_text(done)}' has no element [{elem}]: set the whole list")
            if last:
                raise MessageError(f"'{_text(path)}': set the whole array, not one element")
            obj, done = obj[elem], done + (elem,)
            continue
        slot = _slot_type(obj, elem, done)
        if last:
            setattr(obj, elem, convert(slot, value, _text(path), getattr(obj, elem)))
            return
        child = getattr(obj, elem)
        if isinstance(child, (bytes, tuple)):
            child = list(child)
            setattr(obj, elem, child)
        obj, done = child, done + (elem,)


def has_header(cls: Any) -> bool:
    slots = list(getattr(cls, "__slots__", ()))
    return "header" in slots and cls._slot_types[slots.index("header")] in ("std_msgs/Header", "Header")


def build(cls: Any, assignments: List[Tuple[Path, Any]], stamp: Optional[float]) -> Any:
    """A message of `cls`: defaults, header.stamp = `stamp` when it has a header, then the assignments."""
    msg = cls()
    if stamp is not None and has_header(cls):
        assign(msg, ("header", "stamp"), stamp)
    for path, value in assignments:
        assign(msg, path, value)
    try:
        msg.serialize(io.BytesIO())  # what a publisher would send: catches what the setters could not
    except Exception as exc:  # genpy raises SerializationError, struct.error, TypeError…
        raise MessageError(f"the message does not fit {cls._type}: {exc}") from None
    return msg


_STAMP = ("header", "stamp")


def _absolute(stamp: Any, epoch: float) -> Any:
    """A header stamp in test time as the engine's absolute time; 0 stays the zero stamp."""
    stamp = seconds(stamp)
    if isinstance(stamp, (int, float)) and not isinstance(stamp, bool) and stamp != 0:
        if stamp < 0:
            raise MessageError(f"'header.stamp' is a time (test time in seconds): {stamp!r} is before the "
                               f"test's start (0 s)")
        return epoch + stamp
    return stamp


def in_test_time(fpath: Path, value: Any, epoch: float) -> Any:
    """`value` to assign at `fpath`, with the message's header stamp in test time (test time 0 is `epoch`)
    however it is written: `header.stamp: T` (a path, or a series of it) or `header: {stamp: T}`."""
    if fpath == _STAMP:
        return _absolute(value, epoch)
    if fpath == _STAMP[:1] and isinstance(value, dict) and "stamp" in value:
        return {**value, "stamp": _absolute(value["stamp"], epoch)}
    return value


def field_problems(cls: Any, assignments: List[Tuple[Path, Any]], epoch: float) -> List[Tuple[int, str]]:
    """What is wrong in one message of `cls` (its fields as `assignments`, the stamp in test time): each
    assignment's problem by its index (a field the type lacks, a value it does not allow), and then
    (index -1) what only sending the whole message shows (an integer out of range). Empty: it fits."""
    msg = cls()
    out: List[Tuple[int, str]] = []
    for k, (path, value) in enumerate(assignments):
        try:
            assign(msg, path, in_test_time(path, value, epoch))
        except MessageError as exc:
            out.append((k, str(exc)))
    if not out:
        try:
            msg.serialize(io.BytesIO())
        except Exception as exc:  # genpy raises SerializationError, struct.error, TypeError…
            out.append((-1, f"the message does not fit {cls._type}: {exc}"))
    return out


_REGISTRIES: Dict[str, Any] = {}  # message definitions by type, built from the classes' full text


def field_info(cls: Any, path: Path, tables: Any = (), topic_units: Any = None) -> Any:
    """What the spec's checker knows of `path` in messages of `cls` (rubass.lang.fieldmodel.FieldInfo:
    its kind, 'missing' with why, and its dimension from the unit tables); None when the type's
    definition cannot be read."""
    from ..lang.msgdef import Registry
    from ..lang.msgpath import resolve

    type_name = getattr(cls, "_type", "")
    registry = _REGISTRIES.get(type_name)
    if registry is None:
        try:
            registry = Registry()
            registry.add_full(type_name, cls._full_text)
        except Exception:  # a definition the parser cannot read: the setters still check every value
            return None
        _REGISTRIES[type_name] = registry
    return resolve(registry, type_name, path, tables, topic_units)
