"""What a system model knows of a topic's fields, as the checker asks it (issue: system model).

The checker stays pure: a model built from a recording, the live graph or a model file is handed
to it through this small interface. With no model, every field is of unknown kind and dimension.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Tuple

from .ast import PathElem
from .units import Dimension

try:  # typing.Protocol is Python 3.8+
    from typing import Protocol
except ImportError:  # pragma: no cover
    Protocol = object  # type: ignore[assignment,misc]


@dataclass(frozen=True)
class FieldInfo:
    """The static kind of one field path of a topic.

    kind: 'num' (a number), 'bool', 'str', 'array' (of numbers, or of messages when `elem_kind`
    is 'msg'), 'msg' (a message, not a value), or 'missing' (the type has no such field: `why`
    says what it lacks, e.g. "nav_msgs/Odometry has no field 'twist.linear'").
    dim: the SI dimension of a number (or of an array's elements) when the type says it (REP 103).
    warning: something legal but surely not meant (a slice running past a fixed-size array's end).
    """

    kind: str
    dim: Optional[Dimension] = None
    why: str = ""
    elem_kind: str = ""
    warning: str = ""


class FieldModel(Protocol):
    """A system model, as the checker sees it."""

    def field(self, topic: str, path: Tuple[PathElem, ...]) -> Optional[FieldInfo]:
        """The field at `path` of `topic`'s type; None when the model does not know the topic."""
        ...  # pragma: no cover

    def has_stamp(self, topic: str) -> Optional[bool]:
        """Whether the topic's type has header.stamp; None when the topic is unknown."""
        ...  # pragma: no cover
