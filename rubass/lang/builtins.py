"""Checks of the built-in functions (LANGUAGE.md §4, §10–14): each call becomes a typed node
(Age, Frequency, Rate, ArrayFn, Quant, Latch, Active, Zone …) that the engine runs directly."""
from __future__ import annotations

import functools
import math
from dataclasses import replace
from typing import Any, FrozenSet, List, Tuple

from . import ast
from .errors import a_noun
from .exprtypes import ANY, BOOL, QuantScope, Ty, describe, num
from .geometry import polygon_problem
from .units import COUNT, DIMENSIONLESS, FREQUENCY, LENGTH, MEMORY, TIME, dim_mul, dimension_name

_TOPIC_FORMS = {"frequency": "frequency(topic /t) or frequency(topic /t, 2 s)", "age": "age(topic /t)",
                "stamp_age": "stamp_age(topic /t)"}


def _norm_node(name: str) -> str:
    return name if name.startswith("/") else "/" + name


@functools.lru_cache(maxsize=256)
def _norm_nodes(nodes: Tuple[str, ...]) -> FrozenSet[str]:
    """An entity's nodes, each with its leading '/' (once per entity, not once per node() call)."""
    return frozenset(_norm_node(n) for n in nodes)


class BuiltinChecks:
    """Mixed into ExprChecker: one method per built-in family."""

    scope: Any
    quant: Any

    def _builtin(self, e: ast.Call) -> Tuple[ast.Expr, Any]:
        f = e.func
        if f in ("frequency", "age", "stamp_age"):
            return self._topic_fn(e)
        if f in ("alive", "cpu", "memory"):
            return self._node_fn(e)
        if f in ("min", "max", "len") and len(e.args) == 1:
            return self._array_fn(e)
        if f in ("any", "all", "count"):
            return self._quantifier(e)
        if f == "rate":
            return self._rate(e)
        if f == "latch":
            return self._latch(e)
        if f == "active":
            return self._active(e)
        if f == "polygon":
            return self._polygon(e)
        if f in ("inside", "distance"):
            return self._zone(e)
        self.error(e.span, f"unknown function '{f}'")  # type: ignore[attr-defined]
        return e, ANY

    # -- topics and nodes ------------------------------------------------------------------
    def _dynamic_only(self, e: ast.Call) -> None:
        if not self.scope.dynamic:
            self.error(e.span, f"a constant cannot use {e.func}()")  # type: ignore[attr-defined]

    def _topic_fn(self, e: ast.Call) -> Tuple[ast.Expr, Any]:
        args = list(e.args)
        self._dynamic_only(e)
        max_args = 2 if e.func == "frequency" else 1
        if not args or len(args) > max_args or not isinstance(args[0], ast.TopicRef):
            self.error(e.span, f"{e.func}() is written {_TOPIC_FORMS[e.func]}")  # type: ignore[attr-defined]
            return e, ANY
        ref = args[0]
        if ref.path:
            self.error(ref.span, f"{e.func}() takes a topic, not a field: write "  # type: ignore[attr-defined]
                                 f"'{e.func}(topic {ref.topic})'")
        if e.func == "stamp_age":
            model = getattr(self.scope, "model", None)
            has = model.has_stamp(ref.topic) if model is not None else None
            if has is False:  # its value is unknown (§11): legal, but surely not what was meant
                self.warn(ref.span, f"stamp_age(topic {ref.topic}) is always unknown: the topic's type has no "  # type: ignore[attr-defined]
                                    "header.stamp (use age() for the time since its last message)")
            return ast.StampAge(ref.topic, span=e.span), num(TIME)
        if e.func == "age":
            return ast.Age(ref.topic, span=e.span), num(TIME)
        window = 1.0
        if len(args) == 2:
            lit, wty = self.check(args[1])  # type: ignore[attr-defined]
            if isinstance(lit, ast.Lit) and wty.kind == "any":
                pass  # an unknown unit, a number too large: said where it is written, not again here
            elif not isinstance(lit, ast.Lit) or wty.dim != TIME or wty.bare \
                    or not isinstance(lit.value, float) or not lit.value > 0 or math.isinf(lit.value):
                self.error(args[1].span, "the window of frequency() must be a positive constant time, "  # type: ignore[attr-defined]
                                         "such as '2 s'")
            else:
                window = lit.value
        return ast.Frequency(ref.topic, window, span=e.span), num(FREQUENCY)

    def _node_fn(self, e: ast.Call) -> Tuple[ast.Expr, Any]:
        self._dynamic_only(e)
        if len(e.args) != 1 or not isinstance(e.args[0], ast.NodeRef):
            self.error(e.span, f"{e.func}() is written {e.func}(node /name)")  # type: ignore[attr-defined]
            return e, ANY
        ref = e.args[0]
        nodes = self.scope.nodes
        if nodes is not None and _norm_node(ref.node) not in _norm_nodes(nodes):
            from .errors import did_you_mean
            self.error(ref.span, f"node '{ref.node}' is not in the nodes of entity '{self.scope.entity}' "  # type: ignore[attr-defined]
                                 f"({', '.join(nodes) or 'none declared'}){did_you_mean(ref.node, nodes)}")
        elif nodes is None and self.scope.header_nodes and \
                _norm_node(ref.node) not in _norm_nodes(self.scope.header_nodes):  # a behaviour's: no header of its own
            from .errors import did_you_mean
            self.warn(ref.span, f"node '{ref.node}' is in no entity's header ({', '.join(self.scope.header_nodes)}): "  # type: ignore[attr-defined]
                                f"a misspelt node reads unknown for ever, and what it guards never fires"
                                f"{did_you_mean(ref.node, self.scope.header_nodes)}")
        ty = {"alive": BOOL, "cpu": num(DIMENSIONLESS), "memory": num(MEMORY)}[e.func]
        return ast.NodeStat(ref.node, e.func, span=e.span), ty

    def _rate(self, e: ast.Call) -> Tuple[ast.Expr, Any]:
        self._dynamic_only(e)
        if len(e.args) != 1 or not isinstance(e.args[0], ast.TopicRef) or not e.args[0].path:
            self.error(e.span, "rate() takes a topic field: rate(topic /odom.twist.twist.linear.x)")  # type: ignore[attr-defined]
            return e, ANY
        ref = e.args[0]
        if ast.slice_at(ref.path) >= 0:
            self.error(ref.span, "rate() takes one field, not an array term")  # type: ignore[attr-defined]
            return e, ANY
        _, fty = self.check(ref)  # type: ignore[attr-defined]
        if fty.kind not in ("num", "any"):
            self.error(ref.span, f"rate() needs a number, not a {describe(fty)}")  # type: ignore[attr-defined]
        dim = None if fty.kind != "num" or fty.dim is None else dim_mul(fty.dim, TIME, -1)
        return ast.Rate(ref, span=e.span), num(dim)

    # -- arrays ----------------------------------------------------------------------------
    def _array_term(self, ref: ast.TopicRef) -> Tuple[ast.TopicRef, Tuple[ast.PathElem, ...]]:
        """Split an array term into the array it reads (up to its slice) and the element path."""
        i = ast.slice_at(ref.path)
        if i < 0:
            return ref, ()
        return replace(ref, path=ref.path[:i + 1]), ref.path[i + 1:]

    def _array_fn(self, e: ast.Call) -> Tuple[ast.Expr, Any]:
        arg = e.args[0]
        if not isinstance(arg, ast.TopicRef) or not arg.path:
            what = "an array field such as 'topic /scan.ranges'" if e.func == "len" else \
                "an array field such as 'topic /scan.ranges[0:90]', or at least two values"
            self.error(arg.span, f"{e.func}() of one argument needs {what}")  # type: ignore[attr-defined]
            return e, ANY
        self._dynamic_only(e)
        if self.quant is not None:
            self.error(e.span, f"{e.func}() of an array cannot be used inside {self.quant.func}()")  # type: ignore[attr-defined]
        if self._path_problem(arg):  # type: ignore[attr-defined]
            return e, ANY
        array, elem = self._array_term(arg)
        if e.func == "len" and elem:  # len(status[*].values) counts statuses: not what it seems to say
            self.error(arg.span, f"len() counts the elements of an array: 'topic {arg.topic}{arg.path_text}' would "  # type: ignore[attr-defined]
                                 f"count those of 'topic {array.topic}{array.path_text}' whatever "
                                 f"'{ast.path_suffix(elem).lstrip('.')}' is; write len(topic {array.topic}"
                                 f"{array.path_text}), or index one element: len(topic {arg.topic}"
                                 f"{ast.path_suffix(array.path[:-1])}[0]{ast.path_suffix(elem)})")
            return e, ANY
        ety = self._field_ty(arg, array=True, msg_ok=e.func == "len")  # type: ignore[attr-defined]
        out = ast.ArrayFn(e.func, array, elem, span=e.span)
        if e.func != "len" and ety.kind not in ("num", "any"):  # strings, conditions: as min("a", 1) says
            self._want_num(ety, arg.span, f"{e.func}()")  # type: ignore[attr-defined]
            return out, ANY
        return out, (num(COUNT) if e.func == "len" else num(ety.dim if ety.kind == "num" else None))

    def _quantifier(self, e: ast.Call) -> Tuple[ast.Expr, Any]:
        self._dynamic_only(e)
        if len(e.args) != 1:
            self.error(e.span, f"{e.func}() takes one condition over an array, e.g. "  # type: ignore[attr-defined]
                               f"{e.func}(topic /diagnostics.status[*].level >= 2)")
            return e, ANY
        if self.quant is not None:
            self.error(e.span, f"quantifiers cannot be nested: {e.func}() inside {self.quant.func}()")  # type: ignore[attr-defined]
            return e, ANY
        self.quant = QuantScope(e.func)
        try:
            body, ty = self.check(e.args[0])  # type: ignore[attr-defined]
            self._want_bool(ty, e.args[0].span, f"{e.func}()")  # type: ignore[attr-defined]
            ctx = self.quant
        finally:
            self.quant = None
        for sub in ast.walk(body):
            if isinstance(sub, (ast.For, ast.Within, ast.Latch)):
                word = {ast.For: "'for'", ast.Within: "'within'", ast.Latch: "latch()"}[type(sub)]
                instead = {ast.For: f"({e.func}(…)) for 1 s", ast.Within: f"({e.func}(…)) within 1 s",
                           ast.Latch: f"latch({e.func}(…), …)"}[type(sub)]
                self.error(sub.span, f"{word} cannot be used inside {e.func}(): an element has no history; "  # type: ignore[attr-defined]
                                     f"apply it to the quantifier instead, e.g. {instead}")
                return e, ANY
        nested = any(isinstance(x, ast.Call) and x.func in ("any", "all", "count") for x in ast.walk(body))
        if ctx.array is None and (nested or ctx.reported):
            return e, ANY  # the nested quantifier or the term's path has been reported: not a missing array too
        if ctx.array is None:
            self.error(e.span, f"{e.func}() needs an array term in its condition, such as "  # type: ignore[attr-defined]
                                       "'topic /diagnostics.status[*].level' or 'topic /scan.ranges[0:90]'")
            return e, ANY
        return ast.Quant(e.func, ctx.array, body, span=e.span), (num(COUNT) if e.func == "count" else BOOL)

    # -- logic over time and actions -------------------------------------------------------
    def _latch(self, e: ast.Call) -> Tuple[ast.Expr, Any]:
        self._dynamic_only(e)
        if len(e.args) != 2:
            self.error(e.span, "latch() is written latch(SET, RESET), e.g. "  # type: ignore[attr-defined]
                               "latch(speed > 0.5 m/s, (speed < 0.4 m/s) for 1 s)")
            return e, ANY
        (s, sty), (r, rty) = self.check(e.args[0]), self.check(e.args[1])  # type: ignore[attr-defined]
        self._want_bool(sty, e.args[0].span, "the SET condition of latch()")  # type: ignore[attr-defined]
        self._want_bool(rty, e.args[1].span, "the RESET condition of latch()")  # type: ignore[attr-defined]
        return ast.Latch(s, r, span=e.span), BOOL

    def _active(self, e: ast.Call) -> Tuple[ast.Expr, Any]:
        self._dynamic_only(e)
        arg = e.args[0] if len(e.args) == 1 else None
        if not isinstance(arg, ast.Name) or len(arg.parts) != 1:
            self.error(e.span, "active() takes the name of a declared action: active(stop)")  # type: ignore[attr-defined]
            return e, ANY
        name = arg.parts[0]
        declared = getattr(self.scope, "actions", None)
        if declared is not None and name not in declared:
            from .errors import did_you_mean
            self.error(arg.span, f"active() names '{name}', which is not a declared action: add "  # type: ignore[attr-defined]
                                 f"'action primitive {name};'{did_you_mean(name, declared)}")
        used = getattr(self.scope, "active_uses", None)
        if used is not None:
            used.add(name)
        return ast.Active(name, span=e.span), BOOL

    # -- zones -----------------------------------------------------------------------------
    def _polygon(self, e: ast.Call) -> Tuple[ast.Expr, Any]:
        points: List[Tuple[float, float]] = []
        dims = set()
        ok = True
        for a in e.args:
            if not isinstance(a, ast.Pair):
                self.error(a.span, "a vertex of polygon() is a point '(x, y)', e.g. (4 m, 0 m)")  # type: ignore[attr-defined]
                ok = False
                continue
            coords = []
            for c in (a.x, a.y):
                lit, ty = self.check(c)  # type: ignore[attr-defined]
                if isinstance(lit, ast.Lit) and ty.kind == "any":  # an unknown unit, 1e999: reported already
                    ok = False
                    continue
                if not isinstance(lit, ast.Lit) or not isinstance(lit.value, float) or ty.kind != "num":
                    self.error(c.span, "a vertex's coordinates must be constant lengths, e.g. (4 m, 0 m)")  # type: ignore[attr-defined]
                    ok = False
                    continue
                if not ty.bare and ty.dim != LENGTH:
                    self.error(c.span, f"a vertex's coordinate must be a length, not "  # type: ignore[attr-defined]
                                       f"{a_noun(dimension_name(ty.dim)) if ty.dim is not None else 'a number'}")
                    ok = False
                dims.add("bare" if ty.bare else "length")
                coords.append(lit.value)
            if len(coords) == 2:
                points.append((coords[0], coords[1]))
        if len(dims) > 1:
            self.error(e.span, "polygon() mixes lengths and numbers without a unit: give every "  # type: ignore[attr-defined]
                               "coordinate a unit, or none")
            ok = False
        if ok:
            problem = polygon_problem(points)
            if problem:
                self.error(e.span, problem)  # type: ignore[attr-defined]
                ok = False
        if not ok:
            return e, ANY
        return ast.Lit(tuple(points), span=e.span), Ty("polygon", DIMENSIONLESS if dims == {"bare"} else LENGTH,
                                                       bare=dims == {"bare"})

    def _zone(self, e: ast.Call) -> Tuple[ast.Expr, Any]:
        if len(e.args) != 3:
            self.error(e.span, f"{e.func}() is written {e.func}(X, Y, AREA) with AREA a polygon constant")  # type: ignore[attr-defined]
            return e, ANY
        x, xty = self.check(e.args[0])  # type: ignore[attr-defined]
        y, yty = self.check(e.args[1])  # type: ignore[attr-defined]
        area, aty = self.check(e.args[2])  # type: ignore[attr-defined]
        if aty.kind != "polygon" or not isinstance(area, ast.Lit) or not isinstance(area.value, tuple):
            if aty.kind != "any":
                self.error(e.args[2].span, f"the third argument of {e.func}() must be a polygon, e.g. a "  # type: ignore[attr-defined]
                                           "constant 'const AREA = polygon((0 m, 0 m), (4 m, 0 m), (4 m, 3 m));'")
            return e, ANY
        length = Ty("num", aty.dim, aty.bare)
        for arg, ty, axis in ((e.args[0], xty, "X"), (e.args[1], yty, "Y")):
            self._want_num(ty, arg.span, f"{e.func}() {axis}")  # type: ignore[attr-defined]
            self._same_dim(ty, length, arg.span, f"{e.func}() {axis} is {{}}, the polygon's vertices {{}}")  # type: ignore[attr-defined]
        out = ast.Zone(e.func, x, y, area.value, span=e.span)
        return out, (BOOL if e.func == "inside" else length)


__all__ = ["BuiltinChecks"]
