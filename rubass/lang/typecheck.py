"""Kinds and units of expressions (LANGUAGE.md §4, §7); rewrites names and units into the
checked form the engine runs (Lit, RuleRef), folding constants on the way."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Callable, List, Optional, Tuple, Union

from . import ast
from .errors import Diagnostic, did_you_mean
from .grammar import FUNCTIONS
from .source import Span
from .units import (DIMENSIONLESS, FREQUENCY, MEMORY, TIME, UNITS, Dimension, dim_mul,
                    dim_sqrt, dimension_name)

Value = Union[float, bool, str]


@dataclass(frozen=True)
class Ty:
    """The static type of an expression: a kind and, for numbers, a dimension.

    dim None means the dimension is not known (a topic field); bare marks a number
    written without a unit, which adopts the dimension of what it meets.
    """

    kind: str  # 'bool' | 'num' | 'str' | 'any'
    dim: Optional[Dimension] = None
    bare: bool = False


ANY = Ty("any")
BOOL = Ty("bool")
STR = Ty("str")
BARE = Ty("num", DIMENSIONLESS, bare=True)


def num(d: Optional[Dimension]) -> Ty:
    return Ty("num", d)


Resolution = Union[Tuple[str, ast.Expr, Ty], str]  # ('const'|'rule', expr, ty) or an error message


@dataclass
class Scope:
    """What an expression may see: names, whether topics/nodes are allowed, the entity's nodes."""

    resolve: Callable[[ast.Name], Resolution]
    dynamic: bool = True  # topics, nodes, rules and for are allowed (not in constants)
    nodes: Optional[Tuple[str, ...]] = None  # the entity header, when inside an entity
    entity: str = ""


class ExprChecker:
    """Checks one expression and returns its checked form; diagnostics go to `diags`."""

    def __init__(self, scope: Scope, diags: List[Diagnostic]) -> None:
        self.scope, self.diags = scope, diags

    def error(self, span: Span, msg: str) -> None:
        self.diags.append(Diagnostic(span, msg))

    # -- entry points --------------------------------------------------------------------
    def condition(self, expr: ast.Expr, what: str) -> ast.Expr:
        out, ty = self.check(expr)
        if ty.kind not in ("bool", "any"):
            self.error(expr.span, f"{what} must be a condition (true or false), not a {_describe(ty)}")
        return out

    def check(self, expr: ast.Expr) -> Tuple[ast.Expr, Ty]:
        method = getattr(self, "_" + type(expr).__name__.lower())
        return method(expr)

    # -- leaves --------------------------------------------------------------------------
    def _num(self, e: ast.Num) -> Tuple[ast.Expr, Ty]:
        if e.unit is None:
            return ast.Lit(e.value, span=e.span), BARE
        unit = UNITS.get(e.unit)
        if unit is None:
            self.error(e.span, f"unknown unit '{e.unit}'{did_you_mean(e.unit, UNITS)}")
            return ast.Lit(e.value, span=e.span), ANY
        return ast.Lit(e.value * unit[0], span=e.span), num(unit[1])

    def _bool(self, e: ast.Bool) -> Tuple[ast.Expr, Ty]:
        return ast.Lit(e.value, span=e.span), BOOL

    def _str(self, e: ast.Str) -> Tuple[ast.Expr, Ty]:
        return ast.Lit(e.value, span=e.span), STR

    def _lit(self, e: ast.Lit) -> Tuple[ast.Expr, Ty]:
        return e, _ty_of_value(e.value)

    def _name(self, e: ast.Name) -> Tuple[ast.Expr, Ty]:
        res = self.scope.resolve(e)
        if isinstance(res, str):
            self.error(e.span, res)
            return e, ANY
        kind, target, ty = res
        if kind == "rule" and not self.scope.dynamic:
            self.error(e.span, f"a constant cannot use the rule '{e.text}'")
        return replace(target, span=e.span), ty

    def _topicref(self, e: ast.TopicRef) -> Tuple[ast.Expr, Ty]:
        if not self.scope.dynamic:
            self.error(e.span, "a constant cannot read a topic")
        elif not e.path:
            self.error(e.span, f"'topic {e.topic}' needs a field, e.g. 'topic {e.topic}.data'; "
                               "use age() or frequency() for the topic itself")
        return e, ANY

    def _noderef(self, e: ast.NodeRef) -> Tuple[ast.Expr, Ty]:
        self.error(e.span, f"'node {e.node}' can only be used in alive(), cpu() or memory()")
        return e, ANY

    # -- operators -----------------------------------------------------------------------
    def _unary(self, e: ast.Unary) -> Tuple[ast.Expr, Ty]:
        operand, ty = self.check(e.operand)
        if e.op == "not":
            self._want_bool(ty, e.operand.span, "'not'")
            out: ast.Expr = replace(e, operand=operand)
            return _fold(out), BOOL
        self._want_num(ty, e.operand.span, "'-'")
        return _fold(replace(e, operand=operand)), ty

    def _binary(self, e: ast.Binary) -> Tuple[ast.Expr, Ty]:
        left, lt = self.check(e.left)
        right, rt = self.check(e.right)
        out = replace(e, left=left, right=right)
        op = e.op
        if op in ("and", "or"):
            self._want_bool(lt, e.left.span, f"'{op}'")
            self._want_bool(rt, e.right.span, f"'{op}'")
            return _fold(out), BOOL
        if op in ("==", "!="):
            if lt.kind != rt.kind and "any" not in (lt.kind, rt.kind):
                self.error(e.span, f"'{op}' compares a {_describe(lt)} with a {_describe(rt)}")
            self._same_dim(lt, rt, e.span, "compares {} with {}")
            return _fold(out), BOOL
        if op in ("<", "<=", ">", ">="):
            self._want_num(lt, e.left.span, f"'{op}'")
            self._want_num(rt, e.right.span, f"'{op}'")
            self._same_dim(lt, rt, e.span, "compares {} with {}")
            return _fold(out), BOOL
        self._want_num(lt, e.left.span, f"'{op}'")
        self._want_num(rt, e.right.span, f"'{op}'")
        if op in ("+", "-"):
            self._same_dim(lt, rt, e.span, "cannot add or subtract {} and {}")
            return _fold(out), _join(lt, rt)
        if lt.dim is None or rt.dim is None:
            ty = num(None)
        else:
            ty = Ty("num", dim_mul(lt.dim, rt.dim, 1 if op == "*" else -1), lt.bare and rt.bare)
        return _fold(out), ty

    def _for(self, e: ast.For) -> Tuple[ast.Expr, Ty]:
        if not self.scope.dynamic:
            self.error(e.span, "a constant cannot use 'for'")
        operand, ty = self.check(e.operand)
        self._want_bool(ty, e.operand.span, "'for'")
        duration, dty = self.check(e.duration)
        if not isinstance(duration, ast.Lit) or isinstance(duration.value, (bool, str)):
            self.error(e.duration.span, "the duration of 'for' must be a constant time, such as '0.4 s'")
        elif dty.bare:
            self.error(e.duration.span, f"the duration of 'for' needs a unit of time: write "
                                        f"'{_num_text(duration.value)} s'")
        elif dty.dim != TIME:
            self.error(e.duration.span, f"the duration of 'for' must be a time, not a {_describe(dty)}")
        elif duration.value < 0 or math.isnan(duration.value):
            self.error(e.duration.span, "the duration of 'for' cannot be negative")
        return replace(e, operand=operand, duration=duration), BOOL

    # -- functions -----------------------------------------------------------------------
    def _call(self, e: ast.Call) -> Tuple[ast.Expr, Ty]:
        if e.func not in FUNCTIONS:
            self.error(e.span, f"unknown function '{e.func}'{did_you_mean(e.func, FUNCTIONS)}")
            return e, ANY
        if e.func in ("frequency", "age"):
            return self._topic_fn(e)
        if e.func in ("alive", "cpu", "memory"):
            return self._node_fn(e)
        if e.func in ("min", "max", "len") and len(e.args) == 1:
            return self._array_fn(e)
        arity = {"abs": 1, "sqrt": 1, "hypot": 2, "len": 1}.get(e.func)
        if arity is not None and len(e.args) != arity:
            self.error(e.span, f"{e.func}() takes {arity} argument{'s' if arity > 1 else ''}, "
                               f"got {len(e.args)}")
            return e, ANY
        if e.func in ("min", "max") and len(e.args) < 1:
            self.error(e.span, f"{e.func}() needs an array field or at least two values")
            return e, ANY
        args, tys = [], []
        for a in e.args:
            out, ty = self.check(a)
            self._want_num(ty, a.span, f"{e.func}()")
            args.append(out)
            tys.append(ty)
        result = tys[0]
        for t in tys[1:]:
            self._same_dim(result, t, e.span, f"{e.func}() mixes {{}} and {{}}")
            result = _join(result, t)
        if e.func == "sqrt" and result.dim is not None:
            d = dim_sqrt(result.dim)
            result = Ty("num", d, result.bare) if d is not None else num(None)
        return _fold(replace(e, args=tuple(args))), result

    def _array_fn(self, e: ast.Call) -> Tuple[ast.Expr, Ty]:
        arg = e.args[0]
        if not isinstance(arg, ast.TopicRef):
            what = "an array field such as 'topic /scan.ranges'" if e.func == "len" else \
                "an array field such as 'topic /scan.ranges', or at least two values"
            self.error(arg.span, f"{e.func}() of one argument needs {what}")
            return e, ANY
        self._topicref(arg)
        return e, (BARE if e.func == "len" else num(None))

    def _topic_fn(self, e: ast.Call) -> Tuple[ast.Expr, Ty]:
        args = list(e.args)
        if not self.scope.dynamic:
            self.error(e.span, f"a constant cannot use {e.func}()")
        max_args = 2 if e.func == "frequency" else 1
        if not args or len(args) > max_args or not isinstance(args[0], ast.TopicRef):
            form = "frequency(topic /t) or frequency(topic /t, 2 s)" if e.func == "frequency" else "age(topic /t)"
            self.error(e.span, f"{e.func}() is written {form}")
            return e, ANY
        if args[0].path:
            self.error(args[0].span, f"{e.func}() takes a topic, not a field: write "
                                     f"'{e.func}(topic {args[0].topic})'")
        if len(args) == 2:
            window, wty = self.check(args[1])
            if not isinstance(window, ast.Lit) or wty.dim != TIME or wty.bare \
                    or not isinstance(window.value, float) or window.value <= 0:
                self.error(args[1].span, "the window of frequency() must be a positive constant time, "
                                         "such as '2 s'")
            args[1] = window
        ty = num(FREQUENCY) if e.func == "frequency" else num(TIME)
        return replace(e, args=tuple(args)), ty

    def _node_fn(self, e: ast.Call) -> Tuple[ast.Expr, Ty]:
        if not self.scope.dynamic:
            self.error(e.span, f"a constant cannot use {e.func}()")
        if len(e.args) != 1 or not isinstance(e.args[0], ast.NodeRef):
            self.error(e.span, f"{e.func}() is written {e.func}(node /name)")
            return e, ANY
        ref = e.args[0]
        nodes = self.scope.nodes
        if nodes is not None and _norm(ref.node) not in {_norm(n) for n in nodes}:
            self.error(ref.span, f"node '{ref.node}' is not in the nodes of entity '{self.scope.entity}' "
                                 f"({', '.join(nodes) or 'none declared'}){did_you_mean(ref.node, nodes)}")
        ty = {"alive": BOOL, "cpu": num(DIMENSIONLESS), "memory": num(MEMORY)}[e.func]
        return e, ty

    # -- helpers -------------------------------------------------------------------------
    def _want_bool(self, ty: Ty, span: Span, what: str) -> None:
        if ty.kind not in ("bool", "any"):
            self.error(span, f"{what} needs a condition (true or false), not a {_describe(ty)}")

    def _want_num(self, ty: Ty, span: Span, what: str) -> None:
        if ty.kind not in ("num", "any"):
            self.error(span, f"{what} needs a number, not a {_describe(ty)}")

    def _same_dim(self, a: Ty, b: Ty, span: Span, template: str) -> None:
        if a.kind == b.kind == "num" and a.dim is not None and b.dim is not None \
                and not a.bare and not b.bare and a.dim != b.dim:
            self.error(span, template.format(f"a {dimension_name(a.dim)}", f"a {dimension_name(b.dim)}"))


def _norm(name: str) -> str:
    return name if name.startswith("/") else "/" + name


def _join(a: Ty, b: Ty) -> Ty:
    """The type of a + b (already checked compatible)."""
    if a.kind != "num" or b.kind != "num":  # a topic field takes the dimension of what it meets
        known = a if a.kind == "num" else b
        return known if known.kind == "num" and not known.bare else num(None)
    if a.bare:
        return b
    if b.bare or b.dim is None:
        return a if a.dim is not None else b
    return a


def _describe(ty: Ty) -> str:
    if ty.kind == "num":
        if ty.bare or ty.dim is None:
            return "number"
        return f"number ({dimension_name(ty.dim)})"
    return {"bool": "condition", "str": "string", "any": "value"}[ty.kind]


def _num_text(v: float) -> str:
    return repr(int(v)) if float(v).is_integer() else repr(v)


def _ty_of_value(v: Value) -> Ty:
    if isinstance(v, bool):
        return BOOL
    if isinstance(v, str):
        return STR
    return BARE


_ARITH = {
    "+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b,
    "/": lambda a, b: a / b if b else math.nan,
    "<": lambda a, b: a < b, "<=": lambda a, b: a <= b, ">": lambda a, b: a > b,
    ">=": lambda a, b: a >= b, "==": lambda a, b: a == b, "!=": lambda a, b: a != b,
    "and": lambda a, b: a and b, "or": lambda a, b: a or b,
}
_FUNCS = {"abs": abs, "sqrt": lambda x: math.sqrt(x) if x >= 0 else math.nan,
          "min": min, "max": max, "hypot": math.hypot}


def _fold(e: ast.Expr) -> ast.Expr:
    """Replace an operation on literals by its value, so constants cost nothing at run time."""
    try:
        if isinstance(e, ast.Unary) and isinstance(e.operand, ast.Lit):
            v = e.operand.value
            if e.op == "not" and isinstance(v, bool):
                return ast.Lit(not v, span=e.span)
            if e.op == "-" and isinstance(v, float):
                return ast.Lit(-v, span=e.span)
        if isinstance(e, ast.Binary) and isinstance(e.left, ast.Lit) and isinstance(e.right, ast.Lit):
            a, b = e.left.value, e.right.value
            if type(a) is type(b):
                return ast.Lit(_ARITH[e.op](a, b), span=e.span)
        if isinstance(e, ast.Call) and e.func in _FUNCS and e.args \
                and all(isinstance(a, ast.Lit) and isinstance(a.value, float) for a in e.args):
            return ast.Lit(float(_FUNCS[e.func](*[a.value for a in e.args])), span=e.span)  # type: ignore
    except (ArithmeticError, ValueError, TypeError):
        pass
    return e
