"""ROS 1 message definitions as text (.msg, .srv, a connection header's message_definition),
parsed into field lists, and field paths resolved against them. Pure: no genpy, no rospy."""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Dict, Iterable, Iterator, List, Optional, Tuple

from .errors import RubassError

PRIMITIVES = {"bool", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64",
              "float32", "float64", "string", "time", "duration", "char", "byte"}
INTEGERS = {"int8": (-2 ** 7, 2 ** 7 - 1), "uint8": (0, 2 ** 8 - 1), "int16": (-2 ** 15, 2 ** 15 - 1),
            "uint16": (0, 2 ** 16 - 1), "int32": (-2 ** 31, 2 ** 31 - 1), "uint32": (0, 2 ** 32 - 1),
            "int64": (-2 ** 63, 2 ** 63 - 1), "uint64": (0, 2 ** 64 - 1), "char": (0, 255), "byte": (-128, 127)}
TYPE_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_]*/[A-Za-z_][A-Za-z0-9_]*")
_FIELD = re.compile(r"([A-Za-z_][A-Za-z0-9_/]*)(\[(\d*)\])?\s+([A-Za-z_][A-Za-z0-9_]*)\s*(=.*)?$")
_SEPARATOR = re.compile(r"^={10,}\s*$", re.M)


class DefinitionError(RubassError, ValueError):
    """A definition that cannot be parsed; the message names the type and the line."""

    def __init__(self, message: str, line: int = 0) -> None:
        super().__init__(message)
        self.line = line  # 1-based line within the definition's text; 0: the definition as a whole


@dataclass(frozen=True)
class FieldDef:
    """One field of a message: `float64[] ranges` is FieldDef('ranges', 'float64', True, None)."""

    name: str
    type: str  # a primitive or a full 'package/Type' name
    is_array: bool = False
    length: Optional[int] = None  # fixed-size arrays

    @property
    def is_primitive(self) -> bool:
        return self.type in PRIMITIVES

    def text(self) -> str:
        """As written in a .msg file."""
        suffix = "" if not self.is_array else f"[{self.length if self.length is not None else ''}]"
        return f"{self.type}{suffix} {self.name}"


@dataclass(frozen=True)
class MsgSpec:
    """A message type: its full name and its fields in order (constants left out)."""

    type: str
    fields: Tuple[FieldDef, ...]

    def get(self, name: str) -> Optional[FieldDef]:
        return next((f for f in self.fields if f.name == name), None)

    @property
    def names(self) -> List[str]:
        return [f.name for f in self.fields]

    def text(self) -> str:
        """Its own fields as .msg text (nested types by full name)."""
        return "".join(f.text() + "\n" for f in self.fields)


def _full_type(name: str, package: str) -> str:
    if name in PRIMITIVES or "/" in name:
        return name
    if name == "Header":
        return "std_msgs/Header"
    return f"{package}/{name}"


def definition_lines(text: str) -> Iterator[Tuple[int, str, Optional["re.Match[str]"]]]:
    """(1-based line number, the line, its match: type, [size], size, name, '= constant'; None
    when it cannot be read) for each line of a definition that is not blank or a comment."""
    for number, raw in enumerate(text.splitlines(), 1):
        line = raw.split("#", 1)[0].strip() if "=" not in raw.split("#", 1)[0] else raw.strip()
        if not line or line.startswith("#"):
            continue
        yield number, raw, _FIELD.match(line)


def parse_msg(type_name: str, text: str) -> MsgSpec:
    """The fields of one message's own definition (no embedded dependencies)."""
    if not TYPE_RE.fullmatch(type_name):
        raise DefinitionError(f"'{type_name}' is not a message type name 'package/Type'")
    package = type_name.split("/")[0]
    fields: List[FieldDef] = []
    for number, raw, m in definition_lines(text):
        if m is None:
            raise DefinitionError(f"{type_name}: line {number}: cannot read '{raw.strip()}'", number)
        ftype, arr, size, name, const = m.groups()
        if const is not None:  # a constant, e.g. `uint8 POWER_SUPPLY_STATUS_UNKNOWN = 0`
            continue
        fields.append(FieldDef(name, _full_type(ftype, package), arr is not None,
                               int(size) if size else None))
    return MsgSpec(type_name, tuple(fields))


def parse_full(type_name: str, text: str) -> Dict[str, MsgSpec]:
    """A full definition (genpy's _full_text, a connection header's message_definition): the type
    itself and every `MSG: pkg/Type` after a line of '='."""
    parts = _SEPARATOR.split(text)
    out = {type_name: parse_msg(type_name, parts[0])}
    for part in parts[1:]:
        lines = part.strip("\n").splitlines()
        if not lines:
            continue
        head = lines[0].strip()
        if not head.startswith("MSG:"):
            raise DefinitionError(f"{type_name}: a dependency does not start with 'MSG: package/Type'")
        dep = head[4:].strip()
        out[dep] = parse_msg(dep, "\n".join(lines[1:]))
    return out


def parse_srv(type_name: str, text: str) -> Tuple[MsgSpec, MsgSpec]:
    """A .srv definition: (request, response)."""
    parts = re.split(r"^---\s*$", text, maxsplit=1, flags=re.M)
    if len(parts) != 2:
        raise DefinitionError(f"{type_name}: a service definition needs a '---' line between request and response")
    return parse_msg(type_name + "Request", parts[0]), parse_msg(type_name + "Response", parts[1])


class Registry:
    """Message types by name, from any mix of sources; the first definition of a type wins."""

    def __init__(self) -> None:
        self.types: Dict[str, MsgSpec] = {}
        self.services: Dict[str, Tuple[MsgSpec, MsgSpec]] = {}

    def add_full(self, type_name: str, text: str) -> None:
        for name, spec in parse_full(type_name, text).items():
            self.types.setdefault(name, spec)

    def add(self, spec: MsgSpec) -> None:
        self.types.setdefault(spec.type, spec)

    def add_service(self, type_name: str, request: MsgSpec, response: MsgSpec) -> None:
        self.services.setdefault(type_name, (request, response))

    def get(self, type_name: str) -> Optional[MsgSpec]:
        return self.types.get(type_name)

    def closure(self, roots: Iterable[str]) -> List[MsgSpec]:
        """The types `roots` use, themselves included, each once, that the registry knows."""
        seen: Dict[str, MsgSpec] = {}
        todo = list(roots)
        while todo:
            spec = self.types.get(todo.pop())
            if spec is None or spec.type in seen:
                continue
            seen[spec.type] = spec
            todo += [f.type for f in spec.fields if not f.is_primitive]
        return list(seen.values())
