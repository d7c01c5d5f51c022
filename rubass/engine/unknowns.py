"""Why a rule is unknown although its data came: the computed causes (LANGUAGE.md §5: "the monitor
reports every unknown in its status").

Data-level causes (no message yet, a field the type lacks, a node that cannot be measured) are found
by rubass/actions/status.py from the shell's snapshots. What this module finds is an unknown that the
expression itself makes out of values that are there: a division by zero, NaN from arithmetic
(inf - inf, 0 * inf), sqrt of a negative number, an index past the end of an array, min/max of an
empty array or slice (or of one with only NaN, or no valid laser reading), a field that is NaN, a
frequency window not yet full, a missing header stamp, a rule that is itself unknown.

It walks a rule's expression with the store's values when the status is built (about once a second),
never per message: the evaluation closures stay as they are. The monitor takes a `snapshot` of the
store on the engine's thread (microseconds) and walks it on its own status thread, so a long array
never holds the engine. It writes nothing; stateful operators (`for`, `within`, `latch`) are only
looked into, their state is theirs.
"""
from __future__ import annotations

import math
from typing import Any, Dict, List, Optional, Tuple

from ..lang import ast
from ..lang.fmt import format_expr, format_number
from ..lang.model import CheckedSpec
from ..lang.ops import BINARY, UNARY, scalar_fn
from .arrays import array_fn, element
from .explain import call_text
from .store import Store
from .values import UNKNOWN, as_bool

OPAQUE = object()  # a value this walk does not compute (the state of an operator)
_SCAN = 5_000  # elements of an array a quantifier is looked into at most (~12 ms of the status thread)
_ARITH = ("+", "-", "*", "/")


def snapshot(store: Store) -> Store:
    """A copy of what the walk reads, taken on the engine's thread in microseconds (arrays are immutable
    and shared), so that the walk itself runs on another thread and never holds the engine."""
    snap = Store(store.now, store.origin)
    snap.fields, snap.rules, snap.nodes = dict(store.fields), dict(store.rules), dict(store.nodes)
    snap.last_arrival, snap.watch_start = dict(store.last_arrival), dict(store.watch_start)
    snap.stamps, snap.rates, snap.laser_limits = dict(store.stamps), dict(store.rates), dict(store.laser_limits)
    snap._arrivals = {t: list(a) for t, a in store._arrivals.items()}  # frequency()
    snap._window = dict(store._window)
    return snap


def rule_reasons(spec: CheckedSpec, store: Store,
                 field_errors: Optional[Dict[Tuple[str, str], str]] = None) -> Dict[str, List[str]]:
    """rule key -> why it is unknown, computed from the store, for every rule whose value is neither
    true nor false (empty lists left out). `field_errors`: the engine's (topic, path) -> error, fields
    the data-level reasons already explain (no guess about them here)."""
    out: Dict[str, List[str]] = {}
    for rule in spec.rules:
        v = store.rules.get(rule.key, UNKNOWN)
        if v is True or v is False:
            continue
        try:
            why = reasons(rule.expr, store, getattr(spec, "sources", None), field_errors)
        except Exception:  # noqa: BLE001 - a bug here must never cost the status: the rule says unknown still
            continue
        if why:
            out[rule.key] = why
    return out


def reasons(expr: ast.Expr, store: Store, sources: Any = None,
            field_errors: Optional[Dict[Tuple[str, str], str]] = None) -> List[str]:
    """Why `expr` (or a part of it) is unknown with the store's values, in reading order, each once;
    `sources` (a SourceSet): a quantifier is then quoted as written (with its units)."""
    why: List[str] = []
    walk = _Walk(store, why, sources)
    walk.field_errors = field_errors or {}
    walk.value(expr)
    seen: Dict[str, None] = {}
    for w in why:
        seen.setdefault(w, None)
    return list(seen)


def _num(v: Any) -> str:
    if v is True or v is False:
        return "true" if v else "false"
    if isinstance(v, float):
        return format_number(v) if math.isfinite(v) else ("inf" if v > 0 else "-inf")
    return "unknown" if v is UNKNOWN else repr(v)


def _is_num(v: Any) -> bool:
    return type(v) is float and v == v


class _Walk:
    def __init__(self, store: Store, why: List[str], sources: Any = None) -> None:
        self.store, self.why, self.sources = store, why, sources
        self.item: Any = None  # the element a quantifier's body is looked at for
        self.arr: Optional[ast.TopicRef] = None  # that quantifier's array (to print an element `[*]`)
        self.field_errors: Dict[Tuple[str, str], str] = {}

    def value(self, e: ast.Expr) -> Any:
        """e's value as the engine computes it (UNKNOWN or OPAQUE included), noting computed causes."""
        store = self.store
        if isinstance(e, ast.Lit):
            return e.value
        if isinstance(e, ast.RuleRef):
            v = store.rules.get(e.key, UNKNOWN)
            if v is not True and v is not False:
                self.why.append(f"rule '{e.key}' is unknown (its own status says why)")
            return v
        if isinstance(e, ast.TopicRef):
            return self._field(e)
        if isinstance(e, ast.Unary):
            return self._apply(e, UNARY[e.op], (e.operand,))
        if isinstance(e, ast.Binary):
            return self._binary(e)
        if isinstance(e, ast.Call):
            return self._call(e)
        if isinstance(e, ast.ArrayFn):
            return self._array_fn(e)
        return self._builtin(e)

    def _apply(self, e: ast.Expr, fn: Any, operands: Tuple[ast.Expr, ...]) -> Any:
        vals = [self.value(o) for o in operands]
        if any(v is OPAQUE for v in vals):
            return OPAQUE
        return fn(*vals)

    def _binary(self, e: ast.Binary) -> Any:
        left, right = self.value(e.left), self.value(e.right)
        if left is OPAQUE or right is OPAQUE:
            return OPAQUE
        v = BINARY[e.op](left, right)
        if v is UNKNOWN and e.op in _ARITH and _is_num(left) and _is_num(right):
            if e.op == "/" and right == 0.0:
                self.why.append(f"division by zero: {self._say(e)} is {_num(left)} / {_num(right)}")
            else:  # inf - inf, 0 * inf, inf / inf: not a number
                self.why.append(f"not a number: {self._say(e)} is {_num(left)} {e.op} {_num(right)}")
        return v

    def _call(self, e: ast.Call) -> Any:
        vals = [self.value(a) for a in e.args]
        if any(v is OPAQUE for v in vals):
            return OPAQUE
        v = scalar_fn(e.func)(*vals)
        if v is UNKNOWN and all(_is_num(x) for x in vals):
            if e.func == "sqrt" and vals[0] < 0:
                self.why.append(f"sqrt of a negative number: {self._say(e)} is sqrt({_num(vals[0])})")
            else:
                self.why.append(f"not a number: {self._say(e)} of {', '.join(_num(x) for x in vals)}")
        return v

    def _field(self, e: ast.TopicRef) -> Any:
        store = self.store
        if not e.path:
            return OPAQUE  # a bare topic: only its arrival matters
        v = store.fields.get((e.topic, e.path), UNKNOWN)
        if v is not UNKNOWN or e.topic not in store.last_arrival or (e.topic, str(e.path)) in self.field_errors:
            return v  # a value, or no message yet, or a field error (the data-level reasons say so)
        index = next((i for i, p in enumerate(e.path) if isinstance(p, int)), None)
        if index is not None:
            i = e.path[index]
            array = e.topic + ast.path_suffix(e.path[:index])
            size = self._length(e.topic, e.path[:index])
            assert isinstance(i, int)
            if size is not None and not -size <= i < size:
                self.why.append(f"index out of range: {self._say(e)} in an array of {size} element"
                                f"{'' if size == 1 else 's'} ({array} in the last message)")
            elif size is None:
                need = i + 1 if i >= 0 else -i
                self.why.append(f"{self._say(e)}: {array} in the last message has fewer than {need} element"
                                f"{'' if need == 1 else 's'} (index out of range), or that element is NaN")
            else:
                self.why.append(f"{self._say(e)} is NaN in the last message")
        else:
            self.why.append(f"{self._say(e)} is NaN (or unreadable) in the last message")
        return v

    def _length(self, topic: str, path: Tuple[ast.PathElem, ...]) -> Optional[int]:
        """The length of the array at `path` in the last message, when the store holds it whole."""
        for slot in ((topic, path), (topic, path + (ast.Slice(),))):
            arr = self.store.fields.get(slot)
            if isinstance(arr, (tuple, bytes)):
                return len(arr)
        return None

    def _array_fn(self, e: ast.ArrayFn) -> Any:
        store = self.store
        arr = store.fields.get((e.ref.topic, e.ref.path), UNKNOWN)
        laser = e.ref.path[:1] == ("ranges",) and len(e.ref.path) <= 2 and not e.elem
        limits = (lambda: store.laser_limits.get(e.ref.topic)) if laser else None
        v = array_fn(e.func, lambda: arr, e.elem, limits)()
        if v is not UNKNOWN or not isinstance(arr, (tuple, bytes)):
            return v  # a value, or no array (no message yet, a field error: the data-level reasons)
        at = ast.slice_at(e.ref.path)
        sliced = at >= 0 and e.ref.path[at] != ast.Slice()  # `[*]` is the whole array
        what = f"{e.ref.topic}{e.ref.path_text}"
        if not arr:
            full = self._length(e.ref.topic, e.ref.path[:ast.slice_at(e.ref.path)]) if sliced else None
            self.why.append(f"{self._say(e)} of an empty {'slice' if sliced else 'array'}: {what} has no element"
                            f" in the last message" + (f" (the array has {full})" if full is not None else ""))
        elif limits is not None and limits() is not None:
            lo, hi = limits()  # type: ignore[misc]
            self.why.append(f"{self._say(e)}: no valid reading among the {len(arr)} of {what} (all NaN, +inf or "
                            f"outside [range_min {_num(lo)}, range_max {_num(hi)}], REP 117)")
        else:
            self.why.append(f"{self._say(e)}: no number among the {len(arr)} element{'' if len(arr) == 1 else 's'} "
                            f"of {what} (all NaN)")
        return v

    def _quant(self, e: ast.Quant) -> Any:
        """any/all/count as the engine computes them; when unknown, the first element that makes it so."""
        arr = self.store.fields.get((e.ref.topic, e.ref.path), UNKNOWN)
        if not isinstance(arr, (tuple, bytes)) or len(arr) > _SCAN:
            return OPAQUE
        outer, outer_arr = self.why, self.arr
        self.arr = e.ref
        first: Optional[Tuple[int, List[str]]] = None
        values = []
        try:
            for i, item in enumerate(arr):
                self.item, self.why = item, []
                v = self.value(e.body)
                v = OPAQUE if v is OPAQUE else as_bool(v)
                if v is UNKNOWN and first is None:
                    first = (i, self.why)
                values.append(v)
        finally:
            self.why, self.item, self.arr = outer, None, outer_arr
        if any(v is OPAQUE for v in values):
            return OPAQUE
        if e.func == "count":
            result: Any = UNKNOWN if first is not None else float(sum(v is True for v in values))
        elif e.func == "any":
            result = True if True in values else (UNKNOWN if first is not None else False)
        else:
            result = False if False in values else (UNKNOWN if first is not None else True)
        if result is UNKNOWN and first is not None:
            i, inner = first
            self.why.append(f"{self._written(e)}: its condition is unknown for element {i} of {e.ref.topic}"
                            f"{ast.path_suffix(e.ref.path)}" + (f" ({'; '.join(inner)})" if inner else ""))
        return result

    def _say(self, e: ast.Expr) -> str:
        """An expression printed; inside a quantifier's body its element as `topic /a.data[*]`."""
        try:
            return format_expr(e, 0, self.arr)
        except Exception:  # noqa: BLE001 - a construct the printer does not know: still a reason
            return type(e).__name__

    def _written(self, e: ast.Expr) -> str:
        """A call as written in the spec (units kept, `topic` left out, as ~events' witnesses)."""
        src = self.sources.get(e.span.file) if self.sources is not None else None
        text = call_text(src.text, e.span.start) if src is not None else None
        return text or self._say(e)

    def _builtin(self, e: ast.Expr) -> Any:
        store = self.store
        if isinstance(e, ast.Age):
            return store.age(e.topic)
        if isinstance(e, ast.Frequency):
            v = store.frequency(e.topic, e.window)
            if v is UNKNOWN and e.topic in store.watch_start:
                self.why.append(f"{self._say(e)}: {e.topic} watched for less than its "
                                f"{format_number(e.window)} s window yet")
            return v
        if isinstance(e, ast.StampAge):
            v = store.stamp_age(e.topic)
            if v is UNKNOWN and e.topic in store.last_arrival:
                self.why.append(f"{self._say(e)}: the last message on {e.topic} has a zero header.stamp, or none")
            return v
        if isinstance(e, ast.NodeStat):
            return store.node_value(e.node, e.attr)  # the data-level reasons say why a node is unknown
        if isinstance(e, ast.Rate):
            v = store.rates.get((e.ref.topic, e.ref.path), UNKNOWN)
            if v is UNKNOWN and e.ref.topic in store.last_arrival:
                self.why.append(f"{self._say(e)}: needs two messages on {e.ref.topic} with a number in "
                                f"{e.ref.path_text.lstrip('.')}, at two different times")
            return v
        if isinstance(e, ast.Quant):
            return self._quant(e)
        if isinstance(e, ast.Elem):
            v = element(self.item, e.path)
            if v is UNKNOWN:
                self.why.append(f"{ast.path_suffix(e.path).lstrip('.') or 'it'} is NaN or missing there")
            return v
        for child in ast.children(e):  # for, within, latch, zones: look inside
            self.value(child)
        return OPAQUE
