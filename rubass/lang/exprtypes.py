"""The static types of expressions (LANGUAGE.md §4, §7): a kind and, for numbers, a dimension; how two
join and how a message names them. Shared by typecheck and its builtins."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Dict, Optional

from . import ast
from .errors import a_noun
from .units import DIMENSIONLESS, Dimension, dimension_name


@dataclass(frozen=True)
class Ty:
    """The static type of an expression: a kind and, for numbers, a dimension.

    dim None means the dimension is not known (a topic field); bare marks a number
    written without a unit, which adopts the dimension of what it meets.
    """

    kind: str  # 'bool' | 'num' | 'str' | 'polygon' | 'any'
    dim: Optional[Dimension] = None
    bare: bool = False


ANY = Ty("any")
BOOL = Ty("bool")
STR = Ty("str")
BARE = Ty("num", DIMENSIONLESS, bare=True)


_NUM_TYS: Dict[Optional[Dimension], Ty] = {}


def num(d: Optional[Dimension]) -> Ty:
    """The type of a number of dimension d (one shared Ty per dimension: Ty is immutable)."""
    ty = _NUM_TYS.get(d)
    if ty is None:
        ty = _NUM_TYS.setdefault(d, Ty("num", d))
    return ty


@dataclass
class QuantScope:
    """Inside any/all/count: the array its terms run over (set by the first one)."""

    func: str
    array: Optional[ast.TopicRef] = None
    reported: bool = False  # an array term's path was wrong, and said so: not 'needs an array term' too


def join(a: Ty, b: Ty) -> Ty:
    """The type of a + b, min(a, b), max(a, b), the same whichever comes first: a known dimension
    wins over an unknown one (a topic field takes the dimension of what it meets, §4), which wins
    over a bare number's; two different known dimensions (an error, which typecheck says) give an
    unknown one, so that what uses the sum reports nothing more."""
    if a.kind != "num" or b.kind != "num":  # 'any': an unknown field, or a mistake already said
        known = a if a.kind == "num" else b
        return known if known.kind == "num" and not known.bare else num(None)
    if a.dim is not None and not a.bare and b.dim is not None and not b.bare:
        return a if a.dim == b.dim else num(None)
    for ty in (a, b):
        if ty.dim is not None and not ty.bare:
            return ty
    if a.dim is None or b.dim is None:
        return num(None)
    return a  # both bare


def dim_noun(d: Dimension) -> str:
    """'a length', 'a plain number' (no dimension: a quaternion's component, cpu(), 50 %)."""
    return "a plain number" if d == DIMENSIONLESS else a_noun(dimension_name(d))


def a_describe(ty: Ty) -> str:
    """'a length', 'a plain number', 'a condition': what a value is, its dimension named when known."""
    if ty.kind == "num" and ty.dim is not None and not ty.bare:
        return dim_noun(ty.dim)
    return "a " + describe(ty)


def describe(ty: Ty) -> str:
    if ty.kind == "num":
        if ty.bare or ty.dim is None:
            return "number"
        return f"number ({dimension_name(ty.dim)})"
    return {"bool": "condition", "str": "string", "any": "value", "polygon": "polygon"}[ty.kind]
