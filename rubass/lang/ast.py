"""The RuBaSS abstract syntax tree: frozen dataclasses that hold data and a source span.

Spans never take part in equality, so two parses of the same program compare equal
wherever their layout differs.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterator, Optional, Tuple, Union

from .source import NO_SPAN, Span


def _span() -> Span:
    return field(default=NO_SPAN, compare=False, repr=False)  # type: ignore[return-value]


# ---- expressions -----------------------------------------------------------------------
@dataclass(frozen=True)
class Num:
    value: float
    unit: Optional[str] = None
    span: Span = _span()


@dataclass(frozen=True)
class Bool:
    value: bool
    span: Span = _span()


@dataclass(frozen=True)
class Str:
    value: str
    span: Span = _span()


@dataclass(frozen=True)
class Name:
    """A constant or a rule: `x` or `entity.rule`."""

    parts: Tuple[str, ...]
    span: Span = _span()

    @property
    def text(self) -> str:
        return ".".join(self.parts)


PathElem = Union[str, int]


def path_suffix(path: Tuple[PathElem, ...]) -> str:
    """A field path as written after a topic name: `.pose.position.x`, `.ranges[0]`, `[0]`."""
    return "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in path)


@dataclass(frozen=True)
class TopicRef:
    """`topic /odom.pose.pose.position.x` or `topic /scan.ranges[0]` or bare `topic /t`."""

    topic: str
    path: Tuple[PathElem, ...] = ()
    span: Span = _span()

    @property
    def path_text(self) -> str:
        return path_suffix(self.path)


@dataclass(frozen=True)
class NodeRef:
    node: str
    span: Span = _span()


@dataclass(frozen=True)
class Call:
    func: str
    args: Tuple["Expr", ...]
    span: Span = _span()


@dataclass(frozen=True)
class Unary:
    op: str  # '-' or 'not'
    operand: "Expr"
    span: Span = _span()


@dataclass(frozen=True)
class Binary:
    op: str  # + - * / < <= > >= == != and or
    left: "Expr"
    right: "Expr"
    span: Span = _span()


@dataclass(frozen=True)
class For:
    operand: "Expr"
    duration: "Expr"
    span: Span = _span()


@dataclass(frozen=True)
class Lit:
    """A checked constant, normalised to SI (the checker's output; never parsed)."""

    value: Union[float, bool, str]
    span: Span = _span()


@dataclass(frozen=True)
class RuleRef:
    """A checked reference to a rule by its key 'entity.rule' (the checker's output)."""

    key: str
    span: Span = _span()


Expr = Union[Num, Bool, Str, Name, TopicRef, NodeRef, Call, Unary, Binary, For, Lit, RuleRef]


# ---- declarations ----------------------------------------------------------------------
@dataclass(frozen=True)
class Ident:
    name: str
    span: Span = _span()


@dataclass(frozen=True)
class Import:
    path: str
    span: Span = _span()


@dataclass(frozen=True)
class ActionDecl:
    names: Tuple[Ident, ...]
    span: Span = _span()


@dataclass(frozen=True)
class Const:
    name: Ident
    expr: Expr
    span: Span = _span()


@dataclass(frozen=True)
class Rule:
    name: Ident
    expr: Expr
    span: Span = _span()


@dataclass(frozen=True)
class Entity:
    name: Ident
    nodes: Tuple[Ident, ...]
    rules: Tuple[Rule, ...]
    span: Span = _span()


@dataclass(frozen=True)
class ActionCall:
    name: Ident
    args: Tuple[Expr, ...] = ()
    span: Span = _span()


@dataclass(frozen=True)
class Behaviour:
    cond: Expr
    actions: Tuple[ActionCall, ...]
    span: Span = _span()


Decl = Union[Import, ActionDecl, Const, Entity, Behaviour]


@dataclass(frozen=True)
class Comment:
    """A comment kept for the pretty-printer; not part of the program."""

    text: str
    own_line: bool = True
    span: Span = _span()


@dataclass(frozen=True)
class Spec:
    decls: Tuple[Decl, ...]
    comments: Tuple[Comment, ...] = field(default=(), compare=False)
    file: str = field(default="<string>", compare=False)


def walk(expr: Expr) -> Iterator[Expr]:
    """The expression and every sub-expression in it."""
    stack = [expr]
    while stack:
        e = stack.pop()
        yield e
        stack.extend(children(e))


def children(expr: Expr) -> Tuple[Expr, ...]:
    """The direct sub-expressions of an expression."""
    if isinstance(expr, Call):
        return expr.args
    if isinstance(expr, Unary):
        return (expr.operand,)
    if isinstance(expr, Binary):
        return (expr.left, expr.right)
    if isinstance(expr, For):
        return (expr.operand, expr.duration)
    return ()
