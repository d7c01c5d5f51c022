"""The pretty-printer: one canonical layout, comments kept, parse(fmt(x)) == parse(x)."""
from __future__ import annotations

from typing import Dict, List, Optional, Tuple

from . import ast

WIDTH = 88
_PREC = {"for": 1, "or": 2, "and": 3, "not": 4, "<": 5, "<=": 5, ">": 5, ">=": 5, "==": 5,
         "!=": 5, "+": 6, "-": 6, "*": 7, "/": 7}
_ATOM = 9


def format_number(value: float) -> str:
    """Shortest text that reads back as the same float: 12, 0.4, 1e-06."""
    if value.is_integer() and abs(value) < 1e15:
        return str(int(value))
    return repr(value)


def _quote(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _prec(e: ast.Expr) -> int:
    if isinstance(e, ast.For):
        return 1
    if isinstance(e, ast.Binary):
        return _PREC[e.op]
    if isinstance(e, ast.Unary):
        return 4 if e.op == "not" else 8
    if isinstance(e, (ast.Num, ast.Lit)) and isinstance(e.value, float) and e.value < 0:
        return 8
    return _ATOM


def format_expr(e: ast.Expr, need: int = 0) -> str:
    """An expression on one line, parenthesised only where the grammar needs it."""
    text = _expr(e)
    return f"({text})" if _prec(e) < need else text


def _expr(e: ast.Expr) -> str:
    if isinstance(e, ast.Num):
        return format_number(e.value) + (f" {e.unit}" if e.unit else "")
    if isinstance(e, ast.Lit):
        v = e.value
        if isinstance(v, bool):
            return "true" if v else "false"
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
        return f"{e.func}({', '.join(format_expr(a) for a in e.args)})"
    if isinstance(e, ast.Unary):
        if e.op == "not":
            return f"not {format_expr(e.operand, 4)}"
        return f"-{format_expr(e.operand, 8)}"
    if isinstance(e, ast.Binary):
        p = _PREC[e.op]
        left_need = p + 1 if p == 5 else p
        return f"{format_expr(e.left, left_need)} {e.op} {format_expr(e.right, p + 1)}"
    if isinstance(e, ast.For):
        return f"{format_expr(e.operand, 8)} for {format_expr(e.duration, 8)}"
    raise TypeError(f"cannot format {type(e).__name__}")


def _wrapped(e: ast.Expr, indent: int) -> str:
    """A long expression broken before its top-level 'and'/'or' operators."""
    if isinstance(e, ast.For):
        inner = e.operand
        body = _wrapped(inner, indent + 1) if _prec(inner) < 8 else format_expr(inner)
        if _prec(inner) < 8:
            body = f"({body})"
        return f"{body} for {format_expr(e.duration, 8)}"
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


def _decl(d: ast.Decl, com: _Comments) -> List[str]:
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
    for h in com.header.get(d.span.start, []):  # '&': it stood on the 'rules:' line
        if h.startswith("&") and len(lines) == 2:
            lines[-1] += "  " + h[1:]
        else:
            lines.append("    " + h.lstrip("&"))
    for r in d.rules:
        lines.extend("    " + c for c in com.leading.get(r.span.start, []))
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
    head = f"if ({format_expr(d.cond)}) then {{"
    one = f"{head} {' '.join(calls)} }}" if calls else f"{head} }}"
    if len(one) <= WIDTH:
        return [one]
    if len(head) > WIDTH:
        head = f"if ({_wrapped(d.cond, 4)}) then {{"
    return head.split("\n") + ["  " + c for c in calls] + ["}"]
