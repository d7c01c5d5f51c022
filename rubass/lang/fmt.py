"""The pretty-printer: one canonical layout, comments kept, parse(fmt(x)) == parse(x)."""
from __future__ import annotations

import math
from dataclasses import replace
from typing import Dict, List, Mapping, Optional, Sequence, Tuple

from . import ast

WIDTH = 88
_PREC = {"for": 1, "or": 2, "and": 3, "not": 4, "<": 5, "<=": 5, ">": 5, ">=": 5, "==": 5,
         "!=": 5, "+": 6, "-": 6, "*": 7, "/": 7}
_ATOM = 9


def format_number(value: float) -> str:
    """Shortest text that reads back as the same float: 12, 0.4, 1e-06 (1e999 for a number too
    large, which the checker reports)."""
    if math.isinf(value):
        return "1e999" if value > 0 else "-1e999"
    if value.is_integer() and abs(value) < 1e15:
        return str(int(value))
    return repr(value)


def _num_text(e: ast.Num) -> str:
    """A number literal: as format_number writes its value, but one too small for a float (1e-999,
    read as 0 and an error of the checker's) as written, so that the formatter does not make it 0."""
    if e.value == 0.0 and e.text and any(c in "123456789" for c in e.text.lower().split("e")[0]):
        return ("-" if math.copysign(1.0, e.value) < 0 else "") + e.text
    return format_number(e.value)


def _quote(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _prec(e: ast.Expr) -> int:
    if isinstance(e, (ast.For, ast.Within)):
        return 1
    if isinstance(e, ast.Binary):
        return _PREC[e.op]
    if isinstance(e, ast.Unary):
        return 4 if e.op == "not" else 8
    if isinstance(e, (ast.Num, ast.Lit)) and isinstance(e.value, float) and e.value < 0:
        return 8
    return _ATOM


def format_expr(e: ast.Expr, need: int = 0, arr: Optional[ast.TopicRef] = None) -> str:
    """An expression on one line, parenthesised only where the grammar needs it.

    Checked nodes print as the source that means them (Age as `age(topic /t)`, a polygon
    constant as `polygon(…)`); `arr` is the array an enclosing quantifier runs over."""
    text = _expr(e, arr)
    return f"({text})" if _prec(e) < need else text


def _args(*parts: str) -> str:
    return ", ".join(parts)


def _expr(e: ast.Expr, arr: Optional[ast.TopicRef] = None) -> str:
    f = lambda x, need=0: format_expr(x, need, arr)  # noqa: E731
    if isinstance(e, ast.Num):
        return _num_text(e) + (f" {e.unit}" if e.unit else "")
    if isinstance(e, ast.Lit):
        v = e.value
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, tuple):
            return f"polygon({_args(*(f'({format_number(x)}, {format_number(y)})' for x, y in v))})"
        return _quote(v) if isinstance(v, str) else format_number(v)
    if isinstance(e, ast.Bool):
        return "true" if e.value else "false"
    if isinstance(e, ast.Str):
        return _quote(e.value)
    if isinstance(e, ast.Name):
        return e.text
    if isinstance(e, ast.RuleRef):
        return e.key
    if isinstance(e, ast.TopicRef):
        return f"topic {e.topic}{e.path_text}"
    if isinstance(e, ast.NodeRef):
        return f"node {e.node}"
    if isinstance(e, ast.Call):
        return f"{e.func}({', '.join(f(a) for a in e.args)})"
    if isinstance(e, ast.Unary):
        if e.op == "not":
            return f"not {f(e.operand, 4)}"
        return f"-{f(e.operand, 8)}"
    if isinstance(e, ast.Binary) and e.op in ("and", "or"):
        p = _PREC[e.op]
        terms = ast.chain(e, e.op)  # iteratively: a generated chain may have hundreds of terms
        return f" {e.op} ".join([f(terms[0], p)] + [f(t, p + 1) for t in terms[1:]])
    if isinstance(e, ast.Binary) and _PREC[e.op] == 5:
        return f"{f(e.left, 6)} {e.op} {f(e.right, 6)}"
    if isinstance(e, ast.Binary):
        # a + b - c …: along its left side, without recursion (of a sum of a thousand terms `check`
        # says 'nested too deeply', but `fmt` must still print it)
        p = _PREC[e.op]
        spine: List[ast.Binary] = []
        node: ast.Expr = e
        while isinstance(node, ast.Binary) and _PREC[node.op] == p:
            spine.append(node)
            node = node.left
        text = f(node, p)
        for b in reversed(spine):
            text = f"{text} {b.op} {f(b.right, p + 1)}"
        return text
    if isinstance(e, (ast.For, ast.Within)):
        word = "for" if isinstance(e, ast.For) else "within"
        operand = f(e.operand) if _prec(e.operand) == 1 else f(e.operand, 8)  # `A for 1 s within 2 s`
        return f"{operand} {word} {f(e.duration, 8)}"
    if isinstance(e, ast.Pair):
        return f"({f(e.x)}, {f(e.y)})"
    return _checked(e, arr)


def _checked(e: ast.Expr, arr: Optional[ast.TopicRef]) -> str:
    """The checked built-ins, as their source."""
    f = lambda x: format_expr(x, 0, arr)  # noqa: E731
    if isinstance(e, ast.Age):
        return f"age(topic {e.topic})"
    if isinstance(e, ast.StampAge):
        return f"stamp_age(topic {e.topic})"
    if isinstance(e, ast.Frequency):
        window = "" if e.window == 1.0 else f", {format_number(e.window)} s"
        return f"frequency(topic {e.topic}{window})"
    if isinstance(e, ast.NodeStat):
        return f"{e.attr}(node {e.node})"
    if isinstance(e, ast.Rate):
        return f"rate({f(e.ref)})"
    if isinstance(e, ast.ArrayFn):
        return f"{e.func}(topic {e.ref.topic}{ast.path_suffix(e.ref.path + e.elem)})"
    if isinstance(e, ast.Elem):
        assert arr is not None, "an element outside its quantifier"
        return f"topic {arr.topic}{ast.path_suffix(arr.path + e.path)}"
    if isinstance(e, ast.Quant):
        return f"{e.func}({format_expr(e.body, 0, e.ref)})"
    if isinstance(e, ast.Latch):
        return f"latch({f(e.set)}, {f(e.reset)})"
    if isinstance(e, ast.Active):
        return f"active({e.action})"
    if isinstance(e, ast.Zone):
        return f"{e.func}({f(e.x)}, {f(e.y)}, {_expr(ast.Lit(e.polygon))})"
    raise TypeError(f"cannot format {type(e).__name__}")


def _wrapped(e: ast.Expr, indent: int) -> str:
    """A long expression broken before its top-level 'and'/'or' operators."""
    if isinstance(e, (ast.For, ast.Within)):
        word = "for" if isinstance(e, ast.For) else "within"
        inner = e.operand
        if _prec(inner) == 1:
            body = _wrapped(inner, indent)
        else:
            body = _wrapped(inner, indent + 1) if _prec(inner) < 8 else format_expr(inner)
            if _prec(inner) < 8:
                body = f"({body})"
        return f"{body} {word} {format_expr(e.duration, 8)}"
    return _chain(e, indent)


def _chain(e: ast.Expr, indent: int) -> str:
    if not (isinstance(e, ast.Binary) and e.op in ("and", "or")):
        return format_expr(e)
    parts: List[ast.Expr] = []
    node: ast.Expr = e
    while isinstance(node, ast.Binary) and node.op == e.op:
        parts.append(node.right)
        node = node.left
    parts.append(node)
    parts.reverse()
    need = _PREC[e.op]
    pad = "\n" + " " * indent + e.op + " "
    first = format_expr(parts[0], need)
    return first + "".join(pad + format_expr(p, need + 1) for p in parts[1:])


# ---- declarations and comments -----------------------------------------------------
class _Comments:
    """Comments attached to statements: leading (lines before) and trailing (same line)."""

    def __init__(self, spec: ast.Spec, text: Optional[str]) -> None:
        self.leading: Dict[int, List[str]] = {}
        self.trailing: Dict[int, str] = {}
        self.footer: Dict[int, List[str]] = {}  # before an entity's '}' (key) or file end (-1)
        self.header: Dict[int, List[str]] = {}  # after an entity's 'rules:' ('&': same line)
        if not spec.comments:
            return
        stmts: List[Tuple[int, int, int]] = []  # (start, end, owner entity start or -1)
        for d in spec.decls:
            stmts.append((d.span.start, d.span.end, -1))
            if isinstance(d, ast.Entity):
                stmts.extend((r.span.start, r.span.end, d.span.start) for r in d.rules)
        entities = [d for d in spec.decls if isinstance(d, ast.Entity)]
        for c in spec.comments:
            self._place(c, stmts, entities, text or "")

    def _place(self, c: ast.Comment, stmts: List[Tuple[int, int, int]], entities: List[ast.Entity], text: str) -> None:
        pos = c.span.start
        if not c.own_line:
            ended = [s for s in stmts if s[1] <= pos and "\n" not in text[s[1]:pos]]
            if ended:
                key = max(ended)[0]
                self.trailing[key] = (self.trailing.get(key, "") + " " + c.text).strip()
                return
        inside = [e for e in entities if e.span.start < pos < e.span.end]
        if inside:
            ent = inside[0]
            if not ent.rules or pos < ent.rules[0].span.start:
                if c.own_line and ent.rules:
                    self.leading.setdefault(ent.rules[0].span.start, []).append(c.text)
                else:
                    self.header.setdefault(ent.span.start, []).append(("" if c.own_line else "&") + c.text)
                return
            later = [r for r in ent.rules if r.span.end > pos]
            if later:
                self.leading.setdefault(later[0].span.start, []).append(c.text)
            else:
                self.footer.setdefault(ent.span.start, []).append(c.text)
            return
        later_decls = [s for s in stmts if s[2] == -1 and s[1] > pos]
        if later_decls:
            self.leading.setdefault(min(later_decls)[0], []).append(c.text)
        else:
            self.footer.setdefault(-1, []).append(c.text)


def format_spec(spec: ast.Spec, text: Optional[str] = None) -> str:
    """The canonical text of a spec; give the original text to keep comments in place."""
    com = _Comments(spec, text)
    out: List[str] = []
    prev: Optional[type] = None
    for d in spec.decls:
        if out and not (type(d) is prev and isinstance(d, (ast.Import, ast.ActionDecl, ast.Const))):
            out.append("")
        prev = type(d)
        out.extend(com.leading.get(d.span.start, []))
        lines = _decl(d, com)
        trail = com.trailing.get(d.span.start)
        if trail:
            lines[-1] += "  " + trail
        out.extend(lines)
    if com.footer.get(-1):
        out.extend(([""] if out else []) + com.footer[-1])
    return "\n".join(out) + "\n" if out else ""


def format_attrs(attrs: Mapping[str, Sequence[str]]) -> str:
    """Checked attributes as written (`@id("B-W") @hazard("H1", "H2")`), for /diagnostics."""
    return " ".join(f"@{name}({', '.join(_quote(x) for x in args)})" for name, args in attrs.items())


def _attrs(attrs: Tuple[ast.Attr, ...]) -> List[str]:
    """Attributes on one line before what they annotate (none: no line)."""
    if not attrs:
        return []
    return [" ".join(f"@{a.name}({', '.join(_quote(x) for x in a.args)})" for a in attrs)]


def _decl(d: ast.Decl, com: _Comments) -> List[str]:
    if isinstance(d, (ast.Entity, ast.Behaviour)) and d.attrs:
        return _attrs(d.attrs) + _decl(replace(d, attrs=()), com)
    if isinstance(d, ast.Import):
        return [f"import {_quote(d.path)};"]
    if isinstance(d, ast.ActionDecl):
        return [f"action primitive {', '.join(n.name for n in d.names)};"]
    if isinstance(d, ast.Const):
        return [f"const {d.name.name} = {format_expr(d.expr)};"]
    if isinstance(d, ast.Entity):
        return _entity(d, com)
    return _behaviour(d)


def _entity(d: ast.Entity, com: _Comments) -> List[str]:
    nodes = f": {', '.join(n.name for n in d.nodes)}" if d.nodes else ""
    lines = [f"entity {d.name.name}{nodes} {{", "  rules:"]
    same_line = True  # the next comment of the header may still go on the 'rules:' line
    for h in com.header.get(d.span.start, []):  # '&': it stood on a line of the header, after code
        if h.startswith("&") and same_line:
            lines[-1] += "  " + h[1:]
        else:
            lines.append("    " + h.lstrip("&"))
        same_line = h.startswith("&/*") and same_line  # nothing can follow a '//' comment on its line
    for r in d.rules:
        lines.extend("    " + c for c in com.leading.get(r.span.start, []))
        lines.extend("    " + a for a in _attrs(r.attrs))
        one = f"    {r.name.name}: {format_expr(r.expr)};"
        if len(one) > WIDTH:
            body = _wrapped(r.expr, 6).split("\n")
            one = f"    {r.name.name}:\n      " + "\n".join(body) + ";"
        trail = com.trailing.get(r.span.start)
        lines.extend((one + ("  " + trail if trail else "")).split("\n"))
    lines.extend("    " + c for c in com.footer.get(d.span.start, []))
    lines.append("}")
    return lines


def _behaviour(d: ast.Behaviour) -> List[str]:
    calls = [f"{a.name.name}({', '.join(format_expr(x) for x in a.args)});" if a.args else f"{a.name.name};"
             for a in d.actions]
    label = f"{d.name.name}: " if d.name is not None else ""
    head = f"{label}if ({format_expr(d.cond)}) then {{"
    one = f"{head} {' '.join(calls)} }}" if calls else f"{head} }}"
    if len(one) <= WIDTH:
        return [one]
    if len(head) > WIDTH:
        head = f"{label}if ({_wrapped(d.cond, 4)}) then {{"
    return head.split("\n") + ["  " + c for c in calls] + ["}"]
