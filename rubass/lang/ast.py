"""The RuBaSS abstract syntax tree: frozen dataclasses that hold data and a source span.

Spans never take part in equality, so two parses of the same program compare equal
wherever their layout differs.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterator, List, Optional, Tuple, Union

from .source import NO_SPAN, Span


def _span() -> Span:
    return field(default=NO_SPAN, compare=False, repr=False)  # type: ignore[return-value]


# ---- expressions -----------------------------------------------------------------------
@dataclass(frozen=True)
class Num:
    value: float
    unit: Optional[str] = None
    span: Span = _span()
    text: str = field(default="", compare=False, repr=False)  # as written, for the checker's messages


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


@dataclass(frozen=True)
class Slice:
    """`[A:B]` in a field path (§12): half-open, clipped, negative from the end; `[*]` is `[:]`."""

    start: Optional[int] = None
    stop: Optional[int] = None

    @property
    def text(self) -> str:
        if self.start is None and self.stop is None:
            return "[*]"
        return f"[{'' if self.start is None else self.start}:{'' if self.stop is None else self.stop}]"


@dataclass(frozen=True)
class BadIndex:
    """`[0.5]` in a field path: no index, slice or `[*]`; kept as written (`text`, brackets
    included) for the checker to report at its place, beside the spec's other errors."""

    text: str
    span: Span = _span()


PathElem = Union[str, int, Slice, BadIndex]


def path_suffix(path: Tuple[PathElem, ...]) -> str:
    """A field path as written after a topic name: `.pose.position.x`, `.ranges[0]`, `[0:90]`."""
    return "".join(p.text if isinstance(p, (Slice, BadIndex)) else f"[{p}]" if isinstance(p, int) else f".{p}"
                   for p in path)


def slice_at(path: Tuple[PathElem, ...]) -> int:
    """The position of the slice or `[*]` in a field path, -1 when it has none."""
    for i, p in enumerate(path):
        if isinstance(p, Slice):
            return i
    return -1


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
class Within:
    """`E within T` (§10): E was true at some instant of (t - T, t]."""

    operand: "Expr"
    duration: "Expr"
    span: Span = _span()


@dataclass(frozen=True)
class Pair:
    """`(x, y)`: a vertex, only inside polygon() (§13)."""

    x: "Expr"
    y: "Expr"
    span: Span = _span()


Point = Tuple[float, float]
LitValue = Union[float, bool, str, Tuple[Point, ...]]  # a tuple of points: a polygon (§13)


@dataclass(frozen=True)
class Lit:
    """A checked constant, normalised to SI (the checker's output; never parsed)."""

    value: LitValue
    span: Span = _span()


@dataclass(frozen=True)
class RuleRef:
    """A checked reference to a rule by its key 'entity.rule' (the checker's output)."""

    key: str
    span: Span = _span()


# ---- checked built-ins: the checker's output for the calls of §4 and §10–14 --------------
@dataclass(frozen=True)
class Age:
    topic: str
    span: Span = _span()


@dataclass(frozen=True)
class StampAge:
    topic: str
    span: Span = _span()


@dataclass(frozen=True)
class Frequency:
    topic: str
    window: float = 1.0
    span: Span = _span()


@dataclass(frozen=True)
class NodeStat:
    """alive(), cpu() or memory() of a node: attr is the function's name."""

    node: str
    attr: str
    span: Span = _span()


@dataclass(frozen=True)
class Rate:
    """rate(topic /t.f): the field's change per second over the last two messages (§11)."""

    ref: TopicRef
    span: Span = _span()


@dataclass(frozen=True)
class ArrayFn:
    """min/max/len over an array term: `ref` reads the array (its path ends at the array or its
    slice); `elem` is the field path read in each element (`status[*].level`: ('level',))."""

    func: str
    ref: TopicRef
    elem: Tuple[PathElem, ...] = ()
    span: Span = _span()


@dataclass(frozen=True)
class Elem:
    """Inside a quantifier: the field `path` of the element being visited."""

    path: Tuple[PathElem, ...] = ()
    span: Span = _span()


@dataclass(frozen=True)
class Quant:
    """any/all/count(body) over the elements of the array that `ref` reads (§12)."""

    func: str
    ref: TopicRef
    body: "Expr"
    span: Span = _span()


@dataclass(frozen=True)
class Latch:
    """latch(SET, RESET): an SR latch with set priority, in Kleene logic (§10)."""

    set: "Expr"
    reset: "Expr"
    span: Span = _span()


@dataclass(frozen=True)
class Active:
    """active(ACTION): the declared action is active (§14)."""

    action: str
    span: Span = _span()


@dataclass(frozen=True)
class Zone:
    """inside(X, Y, AREA) (func 'inside') or distance(X, Y, AREA) (func 'distance') (§13)."""

    func: str
    x: "Expr"
    y: "Expr"
    polygon: Tuple[Point, ...]
    span: Span = _span()


Expr = Union[Num, Bool, Str, Name, TopicRef, NodeRef, Call, Unary, Binary, For, Within, Pair, Lit, RuleRef,
             Age, StampAge, Frequency, NodeStat, Rate, ArrayFn, Elem, Quant, Latch, Active, Zone]


# ---- declarations ----------------------------------------------------------------------
@dataclass(frozen=True)
class Ident:
    name: str
    span: Span = _span()


@dataclass(frozen=True)
class Attr:
    """`@id("SR-3")`: a traceability attribute (§15)."""

    name: str
    args: Tuple[str, ...]
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
    attrs: Tuple[Attr, ...] = ()


@dataclass(frozen=True)
class Entity:
    name: Ident
    nodes: Tuple[Ident, ...]
    rules: Tuple[Rule, ...]
    span: Span = _span()
    attrs: Tuple[Attr, ...] = ()


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
    name: Optional[Ident] = None  # `name: if (…)` (§14)
    attrs: Tuple[Attr, ...] = ()


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


def chain(expr: Expr, op: str) -> List[Expr]:
    """The terms of a left-deep chain `a op b op c …` in order (one term when expr is not one)."""
    terms: List[Expr] = []
    node = expr
    while isinstance(node, Binary) and node.op == op:
        terms.append(node.right)
        node = node.left
    terms.append(node)
    terms.reverse()
    return terms


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
    if isinstance(expr, (For, Within)):
        return (expr.operand, expr.duration)
    if isinstance(expr, Pair):
        return (expr.x, expr.y)
    if isinstance(expr, (Rate, ArrayFn)):
        return (expr.ref,)
    if isinstance(expr, Quant):
        return (expr.ref, expr.body)
    if isinstance(expr, Latch):
        return (expr.set, expr.reset)
    if isinstance(expr, Zone):
        return (expr.x, expr.y)
    return ()
