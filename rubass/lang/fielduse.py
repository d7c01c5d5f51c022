"""What a spec needs of each topic field it reads as one value: a number or a condition.

Without a system model the checker cannot know a field's type. The live monitor learns it from
the first message and checks it against these needs (rubass/ros/topics.py): a string or a
boolean where the spec computes with a number, or a number or a string where it needs true or
false, would only ever be unknown, so it is a data error that says so instead.
"""
from __future__ import annotations

from typing import Dict, Iterable, Optional, Tuple

from . import ast

NUMBER, CONDITION = "number", "condition"
Needs = Dict[str, Dict[Tuple[ast.PathElem, ...], str]]  # topic -> field path -> NUMBER | CONDITION

_NUMERIC_OPS = frozenset(("+", "-", "*", "/", "<", "<=", ">", ">="))
_SCALAR_FUNCS = frozenset(("abs", "sqrt", "hypot", "min", "max"))


def field_needs(exprs: Iterable[ast.Expr]) -> Needs:
    """The needs of the fields that rules and conditions (each a condition) read as one value."""
    out: Needs = {}
    for expr in exprs:
        _visit(expr, CONDITION, out)
    return out


def _visit(e: ast.Expr, need: Optional[str], out: Needs) -> None:
    if isinstance(e, ast.TopicRef):
        if e.path and need is not None and ast.slice_at(e.path) < 0:
            out.setdefault(e.topic, {}).setdefault(e.path, need)
        return
    if isinstance(e, (ast.ArrayFn, ast.Quant)):
        return  # arrays and their elements: min/max/len and quantifiers read them as they are
    if isinstance(e, ast.Binary):
        if e.op in _NUMERIC_OPS:
            sides = (NUMBER, NUMBER)
        elif e.op in ("and", "or"):
            sides = (CONDITION, CONDITION)
        else:  # == and != compare values of one kind: a literal says which
            sides = (_kind_of(e.right), _kind_of(e.left))
        _visit(e.left, sides[0], out)
        _visit(e.right, sides[1], out)
        return
    if isinstance(e, ast.Unary):
        _visit(e.operand, CONDITION if e.op == "not" else NUMBER, out)
        return
    if isinstance(e, (ast.For, ast.Within)):
        _visit(e.operand, CONDITION, out)
        _visit(e.duration, NUMBER, out)
        return
    if isinstance(e, ast.Latch):
        _visit(e.set, CONDITION, out)
        _visit(e.reset, CONDITION, out)
        return
    numeric = isinstance(e, (ast.Zone, ast.Rate)) or (isinstance(e, ast.Call) and e.func in _SCALAR_FUNCS)
    child_need = NUMBER if numeric else None
    for child in ast.children(e):
        _visit(child, child_need, out)


def _kind_of(e: ast.Expr) -> Optional[str]:
    """What a literal on the other side of == or != makes of a field: a number or a condition."""
    if isinstance(e, ast.Lit):
        if isinstance(e.value, bool):
            return CONDITION
        if isinstance(e.value, float):
            return NUMBER
    return None
