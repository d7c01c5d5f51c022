"""Why a behaviour started: its true rules (and the rules it reads under `not` that were false) and
the values they read, taken at the transition.

A witness is computed only when a behaviour starts (never for a message that starts nothing),
with readers compiled when the engine is built, so a start only reads values: the rules its
condition uses, directly or through other rules, that are true at that instant, and every topic
field and function value that the condition and those rules read, as the engine's store holds
them then. Labels are written as in a spec without the `topic`/`node` keywords, so a safety
engineer can match them to the rules: `/odom.twist.twist.linear.x`, `age(/cmd_vel)`,
`cpu(controller)`, `min(/scan.ranges[0:90])`. A quantifier or a zone function is read as a whole and
labelled with its own text as written (comments and extra spaces left out):
`count(/scan.ranges[*] < 0.4 m)`, `distance(/odom.pose.pose.position.x, /odom.pose.pose.position.y, CELL)`;
a zone's X and Y are read besides. Values are SI (a share of one core for cpu, bytes for memory);
each function's unit is given beside it.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

from ..lang import ast
from ..lang.model import CheckedSpec
from .store import Store
from .values import UNKNOWN

# functions whose value is a pure read of the store (no state of their own), with their unit


@dataclass(frozen=True)
class Reading:
    """One value a condition read: its label, its value (None when unknown) and its unit."""

    term: str
    value: Any
    unit: str = ""

    def text(self) -> str:
        v = self.value
        if v is None:
            shown = "unknown"
        elif isinstance(v, bool):
            shown = "true" if v else "false"
        elif isinstance(v, float):
            shown = f"{v:.6g}"
        else:
            shown = repr(v) if isinstance(v, str) else str(v)
        return f"{self.term} = {shown}{(' ' + self.unit) if self.unit and v is not None else ''}"


@dataclass(frozen=True)
class Witness:
    """What made a behaviour start: its attributes, the true rules and the values read; `false_rules`:
    the rules the condition reads under `not` that were false (`if (not zone.in_cell)`: the cause)."""

    rules: Tuple[str, ...]
    readings: Tuple[Reading, ...]
    attrs: Tuple[Tuple[str, Tuple[str, ...]], ...] = ()
    name: str = ""  # the behaviour's name (§14), "" when unnamed
    false_rules: Tuple[str, ...] = ()

    def values(self) -> Dict[str, Any]:
        """term -> value (None when unknown) as JSON shows them: valid JSON has no infinity, so an
        infinite value (a laser's no-return, a division's limit) is the string "inf" or "-inf"."""
        return {r.term: (("inf" if r.value > 0 else "-inf") if isinstance(r.value, float) and math.isinf(r.value)
                         else r.value) for r in self.readings}

    def units(self) -> Dict[str, str]:
        return {r.term: r.unit for r in self.readings if r.unit}

    def as_json(self) -> Dict[str, Any]:
        out: Dict[str, Any] = {"name": self.name} if self.name else {}
        out.update({"rules": list(self.rules), "witnesses": self.values(), "units": self.units(),
                    "attrs": {k: list(v) for k, v in self.attrs}})
        if self.false_rules:
            out["false_rules"] = list(self.false_rules)
        return out

    def causes(self) -> str:
        """'true: a, b; false: c' (what a log line or a report says of the rules), '' when none."""
        return "; ".join(f"{what}: {', '.join(keys)}" for what, keys in
                         (("true", self.rules), ("false", self.false_rules)) if keys)


_NODE_UNITS = {"cpu": "cores", "memory": "B", "alive": ""}


def _checked_label(e: ast.Expr) -> Optional[Tuple[str, str]]:
    """(label, unit) of a checked built-in, or None for what is not a reading of its own."""
    if isinstance(e, ast.Age):
        return f"age({e.topic})", "s"
    if isinstance(e, ast.StampAge):
        return f"stamp_age({e.topic})", "s"
    if isinstance(e, ast.Frequency):
        return (f"frequency({e.topic})" if e.window == 1.0 else f"frequency({e.topic}, {e.window:g} s)"), "Hz"
    if isinstance(e, ast.NodeStat):
        return f"{e.attr}({e.node})", _NODE_UNITS.get(e.attr, "")
    if isinstance(e, ast.Rate):
        return f"rate({e.ref.topic}{e.ref.path_text})", "/s"
    if isinstance(e, ast.ArrayFn):
        return f"{e.func}({e.ref.topic}{e.ref.path_text}{ast.path_suffix(e.elem)})", ""
    if isinstance(e, ast.Active):
        return f"active({e.action})", ""
    return None


def label(e: ast.Expr, sources: Any = None) -> Optional[str]:
    """How a witness names a term, or None for what is not a reading. A quantifier or a zone function
    is named by its text in `sources` (a SourceSet) when it can be found there."""
    if isinstance(e, ast.TopicRef):
        return e.topic + e.path_text
    if isinstance(e, (ast.Quant, ast.Zone)):
        src = sources.get(e.span.file) if sources is not None else None
        written = call_text(src.text, e.span.start) if src is not None else None
        if written is not None:
            return written
        if isinstance(e, ast.Quant):
            return f"{e.func}({e.ref.topic}{e.ref.path_text}[*] …)"
        return f"{e.func}({label(e.x) or '…'}, {label(e.y) or '…'}, …)"
    checked = _checked_label(e)
    return checked[0] if checked is not None else None


def _whole_unit(e: ast.Expr) -> str:
    """The unit of a term read as a whole that _checked_label does not know."""
    return "m" if isinstance(e, ast.Zone) and e.func == "distance" else ""


_CALL_LEX = re.compile(r'"(?:[^"\\\n]|\\.)*"|//[^\n]*|/\*[\s\S]*?\*/|[()]')
_KEYWORD = re.compile(r"\b(?:topic|node)\s+(?=[/A-Za-z_~])")


def call_text(text: str, start: int) -> Optional[str]:
    """The text of the call written at `start` (a name and its balanced parentheses) on one line,
    without comments or the `topic`/`node` keywords; None when no call stands there."""
    depth, last = 0, start
    pieces: List[str] = []
    for m in _CALL_LEX.finditer(text, start):
        tok = m.group(0)
        if tok.startswith("/"):  # a comment
            pieces += [text[last:m.start()], " "]
            last = m.end()
        elif tok == "(":
            depth += 1
        elif tok == ")":
            depth -= 1
            if depth <= 0:
                pieces.append(text[last:m.end()])
                out = " ".join("".join(pieces).split())
                out = re.sub(r"\(\s+", "(", re.sub(r"\s+\)", ")", out))
                return _KEYWORD.sub("", out) if depth == 0 else None
    return None


def _json_value(v: Any) -> Any:
    if v is UNKNOWN or v is None:
        return None
    if isinstance(v, float) and not math.isfinite(v):
        return None if math.isnan(v) else v
    if isinstance(v, (bool, int, float, str)):
        return v
    return _ARRAY  # an array: its min/max/len is the reading, not thousands of elements


_ARRAY = object()


class Explainer:
    """Builds witnesses for one engine's behaviours; readers are compiled at the first start."""

    def __init__(self, spec: CheckedSpec, store: Store,
                 compile_term: Callable[[ast.Expr], Callable[[], Any]]) -> None:
        self.spec, self.store, self._compile = spec, store, compile_term
        self._rules = {r.key: r for r in spec.rules}
        self._readers: Dict[int, List[Tuple[str, str, Callable[[], Any]]]] = {}

    def prepare(self) -> None:
        """Compile every reader now (at build time), so that a start only reads values."""
        for b in self.spec.behaviours:
            self._readers_of(b.cond)
        for r in self.spec.rules:
            self._readers_of(r.expr)

    def explain(self, index: int) -> Witness:
        """The witness of behaviour `index` (1-based) at the store's current instant."""
        b = self.spec.behaviours[index - 1]
        true_rules, false_rules = self._causes(b.cond)
        readings: List[Reading] = []
        seen = set()
        for owner in [b.cond] + [self._rules[k].expr for k in true_rules + false_rules]:
            for term, unit, read in self._readers_of(owner):
                if term in seen:
                    continue
                seen.add(term)
                try:
                    value = _json_value(read())
                except Exception:  # a witness must never break the engine
                    value = None
                if value is not _ARRAY:
                    readings.append(Reading(term, value, unit))
        attrs = tuple(sorted((k, tuple(v)) for k, v in (getattr(b, "attrs", None) or {}).items()))
        return Witness(tuple(true_rules), tuple(readings), attrs, getattr(b, "name", "") or "", tuple(false_rules))

    def _causes(self, cond: ast.Expr) -> Tuple[List[str], List[str]]:
        """The rules that made `cond` true, directly or through other rules: those read as they are that
        were true, and those read under `not` (an odd number of them) that were false."""
        found: Dict[bool, List[str]] = {True: [], False: []}
        stack = _rule_refs(cond, True)
        while stack:
            key, positive = stack.pop(0)
            if key in found[positive] or self.store.rules.get(key) is not positive or key not in self._rules:
                continue
            found[positive].append(key)
            stack.extend(_rule_refs(self._rules[key].expr, positive))
        return found[True], found[False]

    def _readers_of(self, expr: ast.Expr) -> List[Tuple[str, str, Callable[[], Any]]]:
        key = id(expr)
        cached = self._readers.get(key)
        if cached is not None:
            return cached
        out: List[Tuple[str, str, Callable[[], Any]]] = []
        for e in _terms(expr):
            term = label(e, getattr(self.spec, "sources", None))
            if term is None:
                continue
            if isinstance(e, ast.TopicRef):
                fields, slot = self.store.fields, (e.topic, e.path)
                out.append((term, "", lambda f=fields, s=slot: f.get(s, UNKNOWN)))  # type: ignore[misc]
                continue
            try:
                fn = self._compile(e)
            except Exception:  # a construct this explainer cannot read alone: leave it out
                continue
            if isinstance(e, ast.Quant) and e.func == "count":
                fn = _as_count(fn)
            checked = _checked_label(e)
            out.append((term, checked[1] if checked is not None else _whole_unit(e), fn))
        self._readers[key] = out
        return out


def _as_count(read: Callable[[], Any]) -> Callable[[], Any]:
    """A count as a whole number (the engine holds it as a float)."""
    def count() -> Any:
        v = read()
        return int(v) if isinstance(v, float) and v.is_integer() else v
    return count


def _rule_refs(expr: ast.Expr, positive: bool) -> List[Tuple[str, bool]]:
    """The rules `expr` reads, in ast.walk's order, each with whether it is read as it is (True) or under
    an odd number of `not` (False), `expr` itself read as `positive`."""
    out: List[Tuple[str, bool]] = []
    stack = [(expr, positive)]
    while stack:
        e, pos = stack.pop()
        if isinstance(e, ast.RuleRef):
            out.append((e.key, pos))
        flip = isinstance(e, ast.Unary) and e.op == "not"
        stack.extend((c, pos != flip) for c in ast.children(e))
    return out


def _terms(expr: ast.Expr) -> Sequence[ast.Expr]:
    """Readings in reading order; a function's own topic argument is not read separately,
    nor is a whole array (its min/max/len is); a quantifier is read as a whole (its body reads one
    element at a time: no single value to show), a zone as a whole and its X and Y besides."""
    out: List[ast.Expr] = []
    todo = [expr]  # a stack, not a recursive closure: a closure that calls itself is a reference
    while todo:    # cycle, and the engine it serves would wait for the cyclic collector
        e = todo.pop()
        if _checked_label(e) is not None or isinstance(e, ast.Quant):
            out.append(e)
        elif isinstance(e, ast.TopicRef):
            if e.path:
                out.append(e)
        else:
            if isinstance(e, ast.Zone):
                out.append(e)
            todo.extend(reversed(ast.children(e)))
    return out
