"""Kinds and units of expressions (LANGUAGE.md §4, §7); rewrites names and units into the
checked form the engine runs (Lit, RuleRef), folding constants on the way."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Callable, Dict, FrozenSet, List, Optional, Set, Tuple, Union

from . import ast
from .builtins import BuiltinChecks
from .errors import Diagnostic, did_you_mean
from .exprtypes import ANY, BARE, BOOL, STR, QuantScope, Ty, a_describe, describe, dim_noun, join, num
from .fieldmodel import FieldModel
from .grammar import FUNCTIONS, bad_index_message
from .ops import BINARY, SCALAR_FUNCTIONS, UNARY, scalar_fn
from .source import Span
from .units import DIMENSIONLESS, TIME, UNITS, dim_mul, dim_sqrt, to_si, unit_suggestion
from .values import UNKNOWN

Value = ast.LitValue
_CONDITION = ("bool", "any")  # the kinds a condition may have
_NUMBER = ("num", "any")  # the kinds a number may have
_ELEM_TYS = {"bool": BOOL, "str": STR}  # the element kinds of an array term that are not numbers


Resolution = Union[Tuple[str, ast.Expr, Ty], str]  # ('const'|'rule', expr, ty) or an error message


@dataclass
class Scope:
    """What an expression may see: names, whether topics/nodes are allowed, the entity's nodes."""

    resolve: Callable[[ast.Name], Resolution]
    dynamic: bool = True  # topics, nodes, rules and for are allowed (not in constants)
    nodes: Optional[Tuple[str, ...]] = None  # the entity header, when inside an entity
    entity: str = ""
    actions: Optional[FrozenSet[str]] = None  # declared actions, for active()
    active_uses: Optional[Set[str]] = None  # filled with the actions active() names
    model: Optional[FieldModel] = None  # a system model: kinds and units of topic fields
    header_nodes: Tuple[str, ...] = ()  # a behaviour's: every node the entities' headers list


class ExprChecker(BuiltinChecks):
    """Checks one expression and returns its checked form; diagnostics go to `diags`."""

    _methods: Dict[type, Callable[..., Tuple[ast.Expr, Ty]]] = {}  # expression type -> its check

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        cls._methods = {}  # a subclass may override a check: a table of its own

    def __init__(self, scope: Scope, diags: List[Diagnostic], warnings: Optional[List[Diagnostic]] = None) -> None:
        self.scope, self.diags = scope, diags
        self.warnings: List[Diagnostic] = [] if warnings is None else warnings
        self.quant: Optional[QuantScope] = None

    def error(self, span: Span, msg: str) -> None:
        self.diags.append(Diagnostic(span, msg))

    def warn(self, span: Span, msg: str) -> None:
        self.warnings.append(Diagnostic(span, msg, "warning"))

    # -- entry points --------------------------------------------------------------------
    def condition(self, expr: ast.Expr, what: str) -> ast.Expr:
        out, ty = self.check(expr)
        if ty.kind not in ("bool", "any"):
            self.error(expr.span, f"{what} must be a condition (true or false), not a {describe(ty)}")
        return out

    def check(self, expr: ast.Expr) -> Tuple[ast.Expr, Ty]:
        method = self._methods.get(type(expr))
        if method is None:
            method = getattr(type(self), "_" + type(expr).__name__.lower())  # _binary for Binary
            self._methods[type(expr)] = method
        errors = len(self.diags)
        out, ty = method(self, expr)
        if type(out) is ast.Lit:
            if type(out.value) is float and not math.isfinite(out.value):
                self.error(expr.span, "this constant expression overflows to infinity: a limit of infinity "
                                      "would never trip (to say 'no limit', leave the rule out)")
                out = ast.Lit(0.0, span=out.span)  # reported once, not again by what uses it
        elif _literal_operands(out) and len(self.diags) == errors \
                and not any(w.span == expr.span for w in self.warnings):  # an error said there: not a warning too
            # _fold left it: unknown whatever the robot does, as at run time (issue 20.1), but said
            self.warn(expr.span, "this constant expression has no value (a division by zero, the square root "
                                 "of a negative number, …): it is unknown, and so is what uses it")
        return out, ty

    # -- leaves --------------------------------------------------------------------------
    def _num(self, e: ast.Num) -> Tuple[ast.Expr, Ty]:
        if not math.isfinite(e.value):  # the parser read 1e999 as infinity
            self.error(e.span, f"the number '{e.text or '1e999'}' is too large (the largest is about 1.8e308)")
            return ast.Lit(0.0, span=e.span), ANY
        if e.value == 0.0 and any(c in "123456789" for c in e.text.lower().split("e")[0]):  # 1e-999
            self.error(e.span, f"the number '{e.text}' is too small: it would be read as 0 (the smallest is about "
                               "5e-324)")
            return ast.Lit(0.0, span=e.span), ANY
        if e.unit is None:
            return ast.Lit(e.value, span=e.span), BARE
        unit = UNITS.get(e.unit)
        if unit is None:
            self.error(e.span, f"unknown unit '{e.unit}'{unit_suggestion(e.unit)}")
            return ast.Lit(e.value, span=e.span), ANY
        value = to_si(e.value, e.unit)
        if not math.isfinite(value):  # 1e308 km: the literal is finite, its value in SI units is not
            self.error(e.span, f"the number '{_written(e)}' is too large once converted to SI units (the largest is "
                               "about 1.8e308): a limit of infinity would never trip")
            return ast.Lit(0.0, span=e.span), ANY
        if value == 0.0 and e.value != 0.0:  # 1e-322 us: 1e-328 s is read as 0
            self.error(e.span, f"the number '{_written(e)}' is too small: once converted to SI units it would be "
                               "read as 0 (the smallest is about 5e-324)")
            return ast.Lit(0.0, span=e.span), ANY
        return ast.Lit(value, span=e.span), num(unit[1])

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
        if isinstance(target, ast.RuleRef):  # built directly: dataclasses.replace is slow in this hot path
            return ast.RuleRef(target.key, e.span), ty
        if isinstance(target, ast.Lit):
            return ast.Lit(target.value, e.span), ty
        return replace(target, span=e.span), ty

    def _topicref(self, e: ast.TopicRef) -> Tuple[ast.Expr, Ty]:
        if not self.scope.dynamic:
            self.error(e.span, "a constant cannot read a topic")
            return e, ANY
        if not e.path:
            self.error(e.span, f"'topic {e.topic}' needs a field, e.g. 'topic {e.topic}.data'; "
                               "use age() or frequency() for the topic itself")
            return e, ANY
        if self._path_problem(e):
            if self.quant is not None:
                self.quant.reported = True
            return e, ANY
        if ast.slice_at(e.path) < 0:
            return e, self._field_ty(e)
        if self.quant is None:
            self.error(e.span, "an array term ('[*]' or '[A:B]') can only be used inside min(), max(), len(), "
                               "any(), all() or count()")
            return e, ANY
        array, elem = self._array_term(e)
        if self.quant.array is None:
            self.quant.array = array
        elif self.quant.array != array:
            first = self.quant.array
            if (first.topic, first.path[:-1]) == (array.topic, array.path[:-1]):
                self.error(e.span, f"two slices of one array in one {self.quant.func}(): 'topic {array.topic}"
                                   f"{array.path_text}' and 'topic {first.topic}{first.path_text}'; the array terms "
                                   "of a quantifier advance together, element by element, so they must be the "
                                   "same slice")
            else:
                self.error(e.span, f"two arrays in one {self.quant.func}(): 'topic {array.topic}{array.path_text}' "
                                   f"and 'topic {first.topic}{first.path_text}'; every array term inside one "
                                   "quantifier must run over the same array")
        return ast.Elem(elem, span=e.span), self._field_ty(e, array=True)

    def _path_problem(self, e: ast.TopicRef) -> bool:
        """Report what the parser let through for this check to say beside the spec's other errors:
        an index that is none ('[0.5]'), a second slice; True when there was one."""
        bad = [p for p in e.path if isinstance(p, ast.BadIndex)]
        for p in bad:
            self.error(p.span, bad_index_message(p.text))
        if not bad and sum(isinstance(p, ast.Slice) for p in e.path) > 1:
            self.error(e.span, "a field path can run over one array only: one '[*]' or '[A:B]'")
            return True
        for p in e.path:  # [100:90], [-1:-3]: empty whatever the array's length
            if isinstance(p, ast.Slice) and p.start is not None and p.stop is not None \
                    and (p.start < 0) == (p.stop < 0) and p.start >= p.stop:
                self.error(e.span, f"a slice '{p.text}' selects no element whatever the array's length: [A:B] takes "
                                   f"elements A to B-1, so A must come before B"
                                   + (f" (did you mean '[{p.stop}:{p.start}]'?)" if p.start != p.stop else ""))
                return True
        return bool(bad)

    def _field_ty(self, e: ast.TopicRef, array: bool = False, msg_ok: bool = False) -> Ty:
        """What the system model says of a field (no model: unknown kind and dimension); array:
        of the elements of an array term (messages are an error there unless msg_ok: len())."""
        model = self.scope.model
        info = model.field(e.topic, e.path) if model is not None else None
        if info is None:
            return ANY
        where = f"'topic {e.topic}{e.path_text}'"
        if info.kind == "missing":
            self.error(e.span, info.why or f"{where} is not a field of its type")
            return ANY
        if info.warning:
            self.warn(e.span, info.warning)
        if array:
            at = ast.slice_at(e.path)
            one = model.field(e.topic, e.path[:at] + (0,) + e.path[at + 1:]) if 0 <= at < len(e.path) - 1 else None
            if one is not None and one.kind == "array":  # rows[*].v: an array in each element (one's is)
                self.error(e.span, f"{where}: a field path runs over one array only, and "
                                   f"'{ast.path_suffix(e.path[at + 1:]).lstrip('.')}' is an array in each element of "
                                   f"'topic {e.topic}{ast.path_suffix(e.path[:at + 1])}'{' (' + one.why + ')' if one.why else ''}; "
                                   f"index one element ('topic {e.topic}{ast.path_suffix(e.path[:at])}[0]"
                                   f"{ast.path_suffix(e.path[at + 1:])}')")
                return ANY
            if info.kind != "array" and at < 0:
                self.error(e.span, f"{where} is not an array{': ' + info.why if info.why else ''}")
                return ANY
            kind = info.elem_kind if info.kind == "array" else info.kind
            if kind == "msg" and not msg_ok:  # an element is a message: the scalar case's error (issue 15)
                if info.kind == "msg":
                    self.error(e.span, f"{where} is a message, not a value{': ' + info.why if info.why else ''}; "
                                       "name one of its fields")
                else:
                    self.error(e.span, f"{where} is an array of messages ({info.why}), not of values: name one "
                                       f"of their fields, e.g. 'topic {e.topic}{e.path_text}[*].FIELD'")
                return ANY
            return _ELEM_TYS.get(kind) or (Ty("num", info.dim) if kind == "num" else ANY)
        if info.kind == "array":
            self.error(e.span, f"{where} is an array{' (' + info.why + ')' if info.why else ''}: use min(), "
                               "max() or len() of it, an index such as [0], or any()/all()/count()")
            return ANY
        if info.kind == "msg":
            self.error(e.span, f"{where} is a message, not a value{': ' + info.why if info.why else ''}; "
                               "name one of its fields")
            return ANY
        if info.kind == "num":
            return Ty("num", info.dim)
        return {"bool": BOOL, "str": STR}.get(info.kind, ANY)

    def _pair(self, e: ast.Pair) -> Tuple[ast.Expr, Ty]:
        self.error(e.span, "a point '(x, y)' can only be a vertex of polygon()")
        return e, ANY

    def _noderef(self, e: ast.NodeRef) -> Tuple[ast.Expr, Ty]:
        self.error(e.span, f"'node {e.node}' can only be used in alive(), cpu() or memory()")
        return e, ANY

    # -- operators -----------------------------------------------------------------------
    def _unary(self, e: ast.Unary) -> Tuple[ast.Expr, Ty]:
        operand, ty = self.check(e.operand)
        if e.op == "not":
            self._want_bool(ty, e.operand.span, "'not'")
            out: ast.Expr = ast.Unary(e.op, operand, e.span)
            return _fold(out), BOOL
        self._want_num(ty, e.operand.span, "'-'")
        return _fold(ast.Unary(e.op, operand, e.span)), ty

    def _chain(self, e: ast.Binary) -> Tuple[ast.Expr, Ty]:
        """A long and/or chain, term by term (a generated spec may have hundreds of terms)."""
        spans = []
        node: ast.Expr = e
        while isinstance(node, ast.Binary) and node.op == e.op:
            spans.append(node.span)
            node = node.left
        spans.reverse()
        terms = ast.chain(e, e.op)
        out, ty = self.check(terms[0])
        if ty.kind not in _CONDITION:
            self._want_bool(ty, terms[0].span, f"'{e.op}'")
        for term, span in zip(terms[1:], spans):
            right, rt = self.check(term)
            if rt.kind not in _CONDITION:
                self._want_bool(rt, term.span, f"'{e.op}'")
            out = _fold(ast.Binary(e.op, out, right, span=span))
        return out, BOOL

    def _within(self, e: ast.Within) -> Tuple[ast.Expr, Ty]:
        return self._postfix(e, "within")

    def _binary(self, e: ast.Binary) -> Tuple[ast.Expr, Ty]:
        if e.op in ("and", "or") and isinstance(e.left, ast.Binary) and e.left.op == e.op:
            return self._chain(e)
        left, lt = self.check(e.left)
        right, rt = self.check(e.right)
        out = ast.Binary(e.op, left, right, e.span)
        op = e.op
        if op in ("and", "or"):
            if lt.kind not in _CONDITION or rt.kind not in _CONDITION:  # the message only when needed
                self._want_bool(lt, e.left.span, f"'{op}'")
                self._want_bool(rt, e.right.span, f"'{op}'")
            return _fold(out), BOOL
        if op in ("==", "!="):
            if lt.kind != rt.kind and "any" not in (lt.kind, rt.kind):
                self.error(e.span, f"'{op}' compares a {describe(lt)} with a {describe(rt)}")
            self._same_dim(lt, rt, e.span, "compares {} with {}")
            return _fold(out), BOOL
        if lt.kind not in _NUMBER or rt.kind not in _NUMBER:  # the message only when needed
            self._want_num(lt, e.left.span, f"'{op}'")
            self._want_num(rt, e.right.span, f"'{op}'")
        if op in ("<", "<=", ">", ">="):
            self._same_dim(lt, rt, e.span, "compares {} with {}")
            return _fold(out), BOOL
        if op in ("+", "-"):
            self._same_dim(lt, rt, e.span, "cannot add or subtract {} and {}")
            return _fold(out), join(lt, rt)
        if lt.dim is None or rt.dim is None:
            ty = num(None)
        else:
            ty = Ty("num", dim_mul(lt.dim, rt.dim, 1 if op == "*" else -1), lt.bare and rt.bare)
        return _fold(out), ty

    def _for(self, e: ast.For) -> Tuple[ast.Expr, Ty]:
        return self._postfix(e, "for")

    def _postfix(self, e: Union[ast.For, ast.Within], word: str) -> Tuple[ast.Expr, Ty]:
        """`E for T` and `E within T`: E a condition, T a constant time, finite and not negative."""
        if not self.scope.dynamic:
            self.error(e.span, f"a constant cannot use '{word}'")
        operand, ty = self.check(e.operand)
        if ty.kind not in _CONDITION:
            self._want_bool(ty, e.operand.span, f"'{word}'")
        warned = len(self.warnings)
        duration, dty = self.check(e.duration)
        if not isinstance(duration, ast.Lit) or not isinstance(duration.value, float):
            if _constant(duration) and dty.kind == "num":
                del self.warnings[warned:]  # 'has no value' is the error below
                self.error(e.duration.span, f"the duration of '{word}' is not a number (a division by zero, "
                                            "or the square root of a negative)")
            else:
                self.error(e.duration.span, f"the duration of '{word}' must be a constant time, such as '0.4 s'")
        elif dty.kind == "any":
            pass  # an unknown unit, said where it is written: not a second error for the same mistake
        elif dty.bare:
            self.error(e.duration.span, f"the duration of '{word}' needs a unit of time: write "
                                        f"'{_num_text(duration.value)} s'")
        elif dty.dim != TIME:
            self.error(e.duration.span, f"the duration of '{word}' must be a time, not {a_describe(dty)}")
        elif duration.value < 0:
            self.error(e.duration.span, f"the duration of '{word}' cannot be negative")
        elif math.isinf(duration.value):
            self.error(e.duration.span, f"the duration of '{word}' must be finite"
                                        + (" (a 'for' of infinity would never be true)" if word == "for" else ""))
        return type(e)(operand, duration, e.span), BOOL  # For or Within

    # -- functions -----------------------------------------------------------------------
    def _call(self, e: ast.Call) -> Tuple[ast.Expr, Ty]:
        if e.func not in FUNCTIONS:
            self.error(e.span, f"unknown function '{e.func}'{did_you_mean(e.func, FUNCTIONS)}")
            return e, ANY
        if e.func not in SCALAR_FUNCTIONS or (e.func in ("min", "max") and len(e.args) == 1):
            return self._builtin(e)
        arity = {"abs": 1, "sqrt": 1, "hypot": 2, "len": 1}.get(e.func)
        if arity is not None and len(e.args) != arity:
            self.error(e.span, f"{e.func}() takes {arity} argument{'s' if arity > 1 else ''}, "
                               f"got {len(e.args)}")
            return e, ANY
        if e.func in ("min", "max") and len(e.args) < 1:
            self.error(e.span, f"{e.func}() needs an array field or at least two values")
            return e, ANY
        args, tys = [], []
        wrong = False
        for a in e.args:
            if e.func in ("min", "max") and self._array_among_values(e.func, a):
                args.append(a)
                tys.append(ANY)
                wrong = True  # said once: not again by what uses the call
                continue
            out, ty = self.check(a)
            if ty.kind not in _NUMBER:
                self._want_num(ty, a.span, f"{e.func}()")
                wrong, ty = True, ANY  # said once: not again by what uses the call
            args.append(out)
            tys.append(ty)
        if wrong:
            return ast.Call(e.func, tuple(args), e.span), ANY
        result = tys[0]
        for t in tys[1:]:
            self._same_dim(result, t, e.span, f"{e.func}() mixes {{}} and {{}}")
            result = join(result, t)
        if e.func == "sqrt" and result.dim is not None:
            result = Ty("num", dim_sqrt(result.dim), result.bare)
        return _fold(ast.Call(e.func, tuple(args), e.span)), result

    # -- helpers -------------------------------------------------------------------------
    def _array_among_values(self, func: str, a: ast.Expr) -> bool:
        """min(topic /scan.ranges[0:90], 1 m): an array where min() of several values takes single
        values; said (True) in words that name both forms. Inside a quantifier an array term is one
        element, a single value."""
        if not isinstance(a, ast.TopicRef) or not a.path or not self.scope.dynamic:
            return False
        if ast.slice_at(a.path) >= 0:
            if self.quant is not None:
                return False  # inside a quantifier an array term is one element
            if self._path_problem(a):
                return True  # a wrong path: said there
        else:
            model = self.scope.model
            info = model.field(a.topic, a.path) if model is not None else None
            if info is None or info.kind != "array":
                return False
        term = f"topic {a.topic}{a.path_text}"
        self.error(a.span, f"{func}() takes either one array or several single values, and '{term}' is an array "
                           f"among values: take its {func} first, e.g. {func}({func}({term}), …)")
        return True

    def _want_bool(self, ty: Ty, span: Span, what: str) -> None:
        if ty.kind not in ("bool", "any"):
            self.error(span, f"{what} needs a condition (true or false), not a {describe(ty)}")

    def _want_num(self, ty: Ty, span: Span, what: str) -> None:
        if ty.kind not in ("num", "any"):
            self.error(span, f"{what} needs a number, not a {describe(ty)}")

    def _same_dim(self, a: Ty, b: Ty, span: Span, template: str) -> None:
        if a.kind == b.kind == "num" and a.dim is not None and b.dim is not None \
                and not a.bare and not b.bare and a.dim != b.dim:
            self.error(span, template.format(dim_noun(a.dim), dim_noun(b.dim)))


def _written(e: ast.Num) -> str:
    """A number literal as written, with its unit: '1e308 km'."""
    sign = "-" if math.copysign(1.0, e.value) < 0 else ""
    return sign + (e.text or _num_text(abs(e.value))) + (f" {e.unit}" if e.unit else "")


def _num_text(v: float) -> str:
    return repr(int(v)) if float(v).is_integer() else repr(v)


def _ty_of_value(v: Value) -> Ty:
    if isinstance(v, bool):
        return BOOL
    if isinstance(v, str):
        return STR
    if isinstance(v, tuple):
        return Ty("polygon", DIMENSIONLESS, bare=True)
    return BARE


def _constant(e: ast.Expr) -> bool:
    """No topic, node, rule or time in it: its value is known before the monitor starts."""
    return all(isinstance(x, (ast.Lit, ast.Unary, ast.Binary, ast.Call, ast.Num)) for x in ast.walk(e))


def _literal_operands(e: ast.Expr) -> bool:
    """An operation on literals only, which _fold could not fold."""
    if isinstance(e, ast.Unary):
        return isinstance(e.operand, ast.Lit)
    if isinstance(e, ast.Binary):
        return isinstance(e.left, ast.Lit) and isinstance(e.right, ast.Lit)
    if isinstance(e, ast.Call):
        return e.func in SCALAR_FUNCTIONS and bool(e.args) and all(isinstance(a, ast.Lit) for a in e.args)
    return False


def _fold(e: ast.Expr) -> ast.Expr:
    """Replace an operation on literals by its value, with the engine's own operator table, so
    constants cost nothing at run time and mean the same. An operation whose value is unknown
    (a division by zero, sqrt of a negative) stays unfolded: the engine finds it unknown too."""
    value: Any = UNKNOWN
    if isinstance(e, ast.Unary) and isinstance(e.operand, ast.Lit):
        value = UNARY[e.op](e.operand.value)
    elif isinstance(e, ast.Binary) and isinstance(e.left, ast.Lit) and isinstance(e.right, ast.Lit):
        value = BINARY[e.op](e.left.value, e.right.value)
    elif isinstance(e, ast.Call) and e.func in SCALAR_FUNCTIONS and e.args \
            and all(isinstance(a, ast.Lit) for a in e.args):
        value = scalar_fn(e.func)(*[a.value for a in e.args])  # type: ignore[union-attr]
    if value is UNKNOWN:
        return e
    return ast.Lit(value, span=e.span)
