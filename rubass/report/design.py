"""A rule's or behaviour's reaction by design: the time on its slowest path from its inputs to its value.

Time enters an expression in five ways: a `for` delays its operand's turning true by its time, a
`within` its turning false; `age()` and `stamp_age()` grow by one second per second after a topic's
last message; `frequency(…, W)` follows a change of a topic's rate within its window W; node statistics
are seen at the monitor's node samples. Every other value changes only when a message comes, so it adds
nothing. A figure is an upper bound or it is not
given: what cannot be bounded here is named ("not computed: …"), never shown as "immediate".
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from typing import Any, Dict, FrozenSet, List, Optional, Tuple

from ..lang import ast
from ..lang.fmt import format_expr
from ..lang.model import CheckedSpec

# alive(), cpu() and memory() are seen at the monitor's node samples (~node_rate, 10 Hz by default): a change
# shows within two samples (cpu() is a share over one sample interval; alive() waits 0.1 s for the node's answer)
NODE_SAMPLE = 0.2
_FLIP = {">": "<=", ">=": "<", "<": ">=", "<=": ">", "==": "!=", "!=": "=="}
_MAX_TOPICS = 8  # subsets of silent topics tried for one comparison (2^8 - 1)


@dataclass
class Design:
    """The times on the slowest path (summed, they are the reaction by design), or why there is no figure."""

    chain: List[float] = field(default_factory=list)
    unknown: List[str] = field(default_factory=list)  # why no figure: each "not computed" reason

    @property
    def total(self) -> float:
        return sum(self.chain)

    def then(self, seconds: float) -> "Design":
        return Design(self.chain + [seconds] if seconds else list(self.chain), list(self.unknown))

    def text(self) -> str:
        """'0.4 s + 1 s', 'immediate', or 'not computed: …'."""
        if self.unknown:
            return "not computed: " + "; ".join(self.unknown)
        return " + ".join(f"{up(v)} s" for v in self.chain) if self.chain else "immediate"


def up(x: float, digits: int = 6) -> str:
    """x in at most `digits` significant digits, rounded up: a bound printed is never below the bound
    (1/3 s is '0.333334', not '0.333333')."""
    text = f"{x:.{digits}g}"
    if x <= 0 or not math.isfinite(x) or float(text) >= x * (1 - 1e-12):  # 0.1 + 0.2 is 0.3, not 0.300001
        return text
    step = 10.0 ** (math.floor(math.log10(x)) - digits + 1)
    for _ in range(3):  # a float product may land just below: step on
        text = f"{math.ceil(x / step) * step:.{digits}g}"
        if float(text) >= x:
            break
        x += step / 2
    return text


def slowest(designs: List[Design]) -> Design:
    """Of several operands, the slowest: no figure when any has none (the slowest could be that one)."""
    reasons: List[str] = []
    for d in designs:
        reasons += [r for r in d.unknown if r not in reasons]
    best = max(designs, key=lambda d: d.total, default=Design())
    return Design(list(best.chain), reasons)


def design(spec: CheckedSpec, expr: ast.Expr, seen: FrozenSet[Any] = frozenset(), true: bool = True) -> Design:
    """The time from the inputs' change to the expression turning true (`true`), or false."""
    if isinstance(expr, ast.For):  # turns true its time after its operand; false with it
        inner = design(spec, expr.operand, seen, true)
        return inner.then(_seconds_of(expr.duration)) if true else inner
    if isinstance(expr, ast.Within):  # true with its operand; false its time after
        inner = design(spec, expr.operand, seen, true)
        return inner if true else inner.then(_seconds_of(expr.duration))
    if isinstance(expr, ast.Latch):  # set at once; reset when RESET is true and SET false
        if true:
            return design(spec, expr.set, seen, True)
        return slowest([design(spec, expr.reset, seen, True), design(spec, expr.set, seen, False)])
    if isinstance(expr, ast.Unary) and expr.op == "not":
        return design(spec, expr.operand, seen, not true)
    if isinstance(expr, ast.RuleRef):
        if expr.key in seen:
            return Design()
        return design(spec, spec.rule(expr.key).expr, seen | {expr.key}, true)
    if isinstance(expr, ast.Active):  # started (or released) by the slowest behaviour with the action
        holders = [b for b in spec.behaviours if b.index not in seen and any(a.name == expr.action for a in b.actions)]
        latched = [b.label for b in holders if b.latched]
        if latched and not true:  # a latched behaviour holds its actions until ~reset, whatever its condition
            return Design(unknown=[f"active({expr.action}) is held by {', '.join(latched)}, latched: it is released "
                                   f"only by ~reset"])
        return slowest([design(spec, b.cond, seen | {b.index}, true) for b in holders])
    if isinstance(expr, ast.NodeStat):
        return Design([NODE_SAMPLE])
    if isinstance(expr, (ast.Quant, ast.Zone)) and _has_time(expr):
        return Design(unknown=[f"{_text(expr)} reads a time inside {_what(expr)}, which the monitor "
                               f"evaluates at its ticks"])
    if isinstance(expr, ast.Binary) and expr.op in _FLIP and (_has_time(expr.left) or _has_time(expr.right)):
        return _comparison(expr, expr.op if true else _FLIP[expr.op])
    return slowest([design(spec, c, seen, true) for c in ast.children(expr)])


def design_chain(spec: CheckedSpec, expr: ast.Expr, seen: FrozenSet[Any] = frozenset()) -> List[float]:
    """The times on an expression's slowest path to turning true (see `design`), of its computed parts
    only: `design(…).unknown` says what is not computed (then the sum is no bound)."""
    return design(spec, expr, seen).chain


def _seconds_of(e: ast.Expr) -> float:
    return float(e.value) if isinstance(e, ast.Lit) and isinstance(e.value, (int, float)) else 0.0


def _has_time(e: ast.Expr) -> bool:
    return any(isinstance(x, (ast.Age, ast.StampAge, ast.Frequency)) for x in ast.walk(e))


def _what(e: ast.Expr) -> str:
    return "a quantifier" if isinstance(e, ast.Quant) else "a zone's point"


def _text(e: ast.Expr) -> str:
    """A sub-expression as written (without units: values in SI), for a reason."""
    try:
        return format_expr(e)
    except (TypeError, AssertionError):
        return type(e).__name__.lower()


def _comparison(e: ast.Binary, op: str) -> Design:
    """When `left op right` turns true. A frequency follows a change of rate within its window: at most
    the window. Ages: the longest time after the last message on any set of the topics read that falling
    silent makes it true, the others' ages taken as 0 (the least they can be), where the difference of
    the sides is monotone in every age (else no figure)."""
    freqs = [x for x in ast.walk(e) if isinstance(x, ast.Frequency)]
    ages = [x for x in ast.walk(e) if isinstance(x, (ast.Age, ast.StampAge))]
    label = _text(e)
    ticked = [x for x in ast.walk(e) if isinstance(x, (ast.Quant, ast.Zone)) and _has_time(x)]
    if ticked:
        return Design(unknown=[f"{_text(ticked[0])} reads a time inside {_what(ticked[0])}, which the monitor "
                               f"evaluates at its ticks"])
    if freqs and ages:
        return Design(unknown=[f"{label} mixes frequency() and age()"])
    if freqs:
        return Design([max(f.window for f in freqs)])
    if op in ("==", "!="):
        return Design(unknown=[f"{label}: an age compared with == or != (it crosses a value, it does not stay)"])
    diff = ast.Binary("-", e.left, e.right) if op in (">", ">=") else ast.Binary("-", e.right, e.left)
    strict = op in (">", "<")
    signs, why = _signs(diff)
    if why:
        return Design(unknown=[f"{label}: {why}"])
    if all(s < 0 for s in signs.values()):
        return Design()  # true when a message comes (an age falls), not by waiting
    if any(s < 0 for s in signs.values()):
        against = sorted(t for t, s in signs.items() if s < 0)
        return Design(unknown=[f"{label}: the age of {', '.join(against)} counts against it (it turns true by "
                               f"one topic's silence only while another keeps publishing)"])
    topics = sorted(signs)
    if len(topics) > _MAX_TOPICS:
        return Design(unknown=[f"{label} reads the ages of {len(topics)} topics (at most {_MAX_TOPICS} are solved)"])
    worst = 0.0
    for n in range(1, len(topics) + 1):
        for silent in itertools.combinations(topics, n):
            t = _first_true(_linear(diff, frozenset(silent)), strict)
            if math.isfinite(t):
                worst = max(worst, t)
    return Design([worst] if worst > 0 else [])


def _signs(e: ast.Expr) -> Tuple[Dict[str, int], str]:
    """How e moves with each topic's age: +1 grows, -1 falls; a reason when it does not move one way."""
    if isinstance(e, (ast.Age, ast.StampAge)):
        return {e.topic: 1}, ""
    if isinstance(e, ast.Lit):
        return ({}, "") if isinstance(e.value, (int, float)) else ({}, f"{_text(e)} is not a number")
    if not _has_time(e):
        return {}, f"its limit {_text(e)} is read from messages (the threshold is not a constant)"
    if isinstance(e, ast.Unary) and e.op == "-":
        inner, why = _signs(e.operand)
        return {k: -v for k, v in inner.items()}, why
    if isinstance(e, ast.Binary) and e.op in ("+", "-"):
        return _merge(_signs(e.left), _signs(e.right), -1 if e.op == "-" else 1)
    if isinstance(e, ast.Binary) and e.op in ("*", "/"):
        if e.op == "/" and _has_time(e.right):
            return {}, f"{_text(e)} divides by an age"
        const, timed = (e.left, e.right) if e.op == "*" and not _has_time(e.left) else (e.right, e.left)
        if _has_time(const) or not (isinstance(const, ast.Lit) and isinstance(const.value, (int, float))):
            return {}, f"{_text(e)} is not a constant times an age"
        inner, why = _signs(timed)
        k = float(const.value)
        return ({}, f"{_text(e)} multiplies by 0") if k == 0 else ({t: s if k > 0 else -s for t, s in inner.items()}, why)
    if isinstance(e, ast.Call) and e.func in ("min", "max"):
        out: Tuple[Dict[str, int], str] = ({}, "")
        for a in e.args:
            out = _merge(out, _signs(a), 1)
        return out
    return {}, f"{_text(e)} is not a sum, difference, constant multiple, min or max of ages"


def _merge(a: Tuple[Dict[str, int], str], b: Tuple[Dict[str, int], str], sign: int) -> Tuple[Dict[str, int], str]:
    if a[1] or b[1]:
        return {}, a[1] or b[1]
    out = dict(a[0])
    for t, s in b[0].items():
        if out.get(t, sign * s) != sign * s:
            return {}, f"the age of {t} counts both for and against it"
        out[t] = sign * s
    return out, ""


# ---- piecewise-linear functions of the time t since the silence began: [(start, a, b)], a + b*t ------
Pieces = List[Tuple[float, float, float]]


def _linear(e: ast.Expr, silent: FrozenSet[str]) -> Pieces:
    """e with the ages of the silent topics = t and the others = 0 (only the forms _signs accepts)."""
    if isinstance(e, (ast.Age, ast.StampAge)):
        return [(0.0, 0.0, 1.0 if e.topic in silent else 0.0)]
    if isinstance(e, ast.Lit):
        return [(0.0, float(e.value), 0.0)]  # type: ignore[arg-type]
    if isinstance(e, ast.Unary):
        return _scale(_linear(e.operand, silent), -1.0)
    if isinstance(e, ast.Binary) and e.op in ("+", "-"):
        right = _linear(e.right, silent)
        return _combine(_linear(e.left, silent), right if e.op == "+" else _scale(right, -1.0), None)
    if isinstance(e, ast.Binary):
        timed_left = e.op == "/" or _has_time(e.left)
        const = float((e.right if timed_left else e.left).value)  # type: ignore[union-attr]
        return _scale(_linear(e.left if timed_left else e.right, silent), 1 / const if e.op == "/" else const)
    assert isinstance(e, ast.Call)
    out = _linear(e.args[0], silent)
    for a in e.args[1:]:
        out = _combine(out, _linear(a, silent), e.func)
    return out


def _scale(f: Pieces, k: float) -> Pieces:
    return [(s, a * k, b * k) for s, a, b in f]


def _at(f: Pieces, t: float) -> Tuple[float, float]:
    """The (a, b) of the piece holding t."""
    piece = f[0]
    for p in f:
        if p[0] <= t:
            piece = p
    return piece[1], piece[2]


def _combine(f: Pieces, g: Pieces, pick: Optional[str]) -> Pieces:
    """f + g (pick None), or min/max of f and g, split where they cross."""
    starts = sorted({s for s, _, _ in f} | {s for s, _, _ in g})
    out: Pieces = []
    for i, s in enumerate(starts):
        end = starts[i + 1] if i + 1 < len(starts) else math.inf
        (a1, b1), (a2, b2) = _at(f, s), _at(g, s)
        if pick is None:
            out.append((s, a1 + a2, b1 + b2))
            continue
        cuts = [s]
        if b1 != b2:
            x = (a2 - a1) / (b1 - b2)
            if s < x < end:
                cuts.append(x)
        for j, c in enumerate(cuts):
            mid = (c + cuts[j + 1]) / 2 if j + 1 < len(cuts) else (c + end) / 2 if end < math.inf else c + 1
            v1, v2 = a1 + b1 * mid, a2 + b2 * mid
            first = (v1 <= v2) == (pick == "min")
            out.append((c, a1, b1) if first else (c, a2, b2))
    return out


def _first_true(f: Pieces, strict: bool) -> float:
    """The first t >= 0 from which f > 0 (or >= 0); inf when never."""
    for i, (s, a, b) in enumerate(f):
        end = f[i + 1][0] if i + 1 < len(f) else math.inf
        v = a + b * s
        if v > 0 or (v == 0 and (not strict or b > 0)):
            return s
        if b > 0:
            root = -a / b
            if root < end:
                return root
    return math.inf
