"""A fast parser for valid specs: one regex tokenizer and recursive descent with precedence
climbing, building exactly the AST of the pyparsing grammar (grammar.py), spans included.

pyparsing stays the reference grammar and the source of every syntax-error message:
grammar.parse_source tries this parser first and, whenever it does not accept a text (NotAccepted,
or any other exception), parses the text again with pyparsing, which then either succeeds or
reports the error. So this parser may leave rare constructs to pyparsing, but must never accept a
text pyparsing rejects nor build a different tree (test/unit/test_fastparse.py checks both).
It reads the comment-stripped text (grammar._strip_comments) and reuses the grammar's regexes,
keywords, precedences and token conversions, so both parsers share one definition of each token.
"""
from __future__ import annotations

import re
import string
import sys
from bisect import bisect_right
from typing import Any, List, Optional, Tuple

from . import ast
from .grammar import (
    _BIN_PREC, _GRAPH_RE, _IDENT_RE, _NOT_PREC, _NUM_RE, _PATH_RE, _UNIT_RE, KEYWORDS, _number,
    _string, _topic,
)
from .source import Source, Span

_WS = "[ \t\r\n]*"  # pyparsing's default whitespace (comments are blanked out before parsing)
_TOKEN = re.compile(
    rf"{_WS}(?:(?P<num>{_NUM_RE})|(?P<word>{_IDENT_RE}(?:\.{_IDENT_RE})?)"
    r'|(?P<str>"(?:[^"\\\n]|\\.)*")|(?P<punct><=|>=|==|!=|[-<>+*/(){};:,@=])|(?P<eof>\Z))'
)
_SKIP = re.compile(_WS)
_UNIT = re.compile(rf"{_WS}({_UNIT_RE})")
_TOPIC_NAME = re.compile(rf"{_WS}({_GRAPH_RE}{_PATH_RE})")
_NODE_NAME = re.compile(rf"{_WS}({_GRAPH_RE})")
# pyparsing's Keyword refuses a keyword that follows one of these characters without a space
_KEYWORD_CHARS = frozenset(string.ascii_letters + string.digits + "_$")

# About how many interpreter frames pyparsing spends on one level of each nesting (a little more
# than pyparsing 3.0 does): past 40 % of the stack left, pyparsing decides (it may then report
# "nested too deeply", where this parser would not)
_PAREN, _CALL, _MINUS, _NOT = 20, 28, 8, 2


def _stack_depth() -> int:
    frame, depth = sys._getframe(), 0
    while frame is not None:
        frame, depth = frame.f_back, depth + 1  # type: ignore[assignment]
    return depth


class NotAccepted(Exception):
    """This parser does not accept the text: pyparsing decides (and reports any error)."""


class _Parser:
    """Recursive descent over a lazily lexed token stream; one token of lookahead."""

    def __init__(self, text: str, source: Source) -> None:
        self.s, self.src, self.name = text, source, source.name
        self.lines = source._line_starts  # the offset of each line's start
        self.kind: str = ""
        self.text: Optional[str] = ""
        self.unit: Optional[str] = None
        self.start = self.end = 0
        self.depth, self.max_depth = 0, (sys.getrecursionlimit() - _stack_depth()) * 2 // 5
        self.lex(0)

    # ---- tokens ----------------------------------------------------------------------
    def lex(self, pos: int) -> None:
        """Make the token at pos (after whitespace) the current one."""
        m = _TOKEN.match(self.s, pos)
        if m is None:  # a character no token starts with
            self.kind, self.text = "error", None
            self.start = self.end = _SKIP.match(self.s, pos).end()  # type: ignore[union-attr]
            return
        kind = m.lastgroup or ""
        start, end, text = m.start(kind), m.end(), m.group(kind)
        if kind == "num":
            u = _UNIT.match(self.s, end)
            self.unit = None
            if u is not None and u.group(1) not in KEYWORDS:
                self.unit, end = u.group(1), u.end()
        elif kind == "word" and start == pos and pos and self.s[pos - 1] in _KEYWORD_CHARS:
            kind, text = "error", None  # '5for': pyparsing's Keyword would not match there
        self.kind, self.text, self.start, self.end = kind, text, start, end

    def advance(self) -> None:
        self.lex(self.end)

    def expect(self, punct: str) -> int:
        """Consume the punctuation or keyword punct; its offset."""
        if self.text != punct:
            raise NotAccepted(punct)
        start = self.start
        self.lex(self.end)
        return start

    def span(self, start: int, end: int = -1) -> Span:
        """Source.span(start, end), without its clamping (offsets here are inside the text)."""
        line = bisect_right(self.lines, start)
        return Span(self.name, line, start - self.lines[line - 1] + 1, start, start if end < 0 else end)

    def ident(self) -> ast.Ident:
        """A name that is not a keyword (pyparsing: ident_node, label_name)."""
        text = self.text
        if self.kind != "word" or text in KEYWORDS or "." in text:  # type: ignore[operator]
            raise NotAccepted("name")
        node = ast.Ident(text, span=self.span(self.start))  # type: ignore[arg-type]
        self.lex(self.end)
        return node

    def relex(self, pattern: "re.Pattern[str]", pos: int) -> Tuple[str, int]:
        """A context-dependent token (topic or node name) after pos; the token after it becomes current."""
        m = pattern.match(self.s, pos)
        if m is None:
            raise NotAccepted("name")
        self.lex(m.end())
        return m.group(1), m.start(1)

    def str_value(self) -> str:
        if self.kind != "str":
            raise NotAccepted("string")
        node = _string(self.s, self.start, (self.text,))
        self.lex(self.end)
        return node.value

    # ---- declarations ----------------------------------------------------------------
    def spec(self) -> Tuple[ast.Decl, ...]:
        decls: List[ast.Decl] = []
        while self.kind != "eof":
            decls.append(self.decl())
        return tuple(decls)

    def decl(self) -> ast.Decl:
        start, word = self.start, self.text
        if word == "import":
            self.advance()
            path = self.str_value()
            return ast.Import(path, span=self.span(start, self.expect(";") + 1))
        if word == "action":
            self.advance()
            self.expect("primitive")
            names = [self.ident()]
            while self.text == ",":
                self.advance()
                names.append(self.ident())
            return ast.ActionDecl(tuple(names), span=self.span(start, self.expect(";") + 1))
        if word == "const":
            self.advance()
            name = self.ident()
            self.expect("=")
            expr = self.expr()
            return ast.Const(name, expr, span=self.span(start, self.expect(";") + 1))
        attrs = self.attrs()
        if self.text == "entity":
            return self.entity(start, attrs)
        return self.behaviour(start, attrs)

    def attrs(self) -> Tuple[ast.Attr, ...]:
        out: List[ast.Attr] = []
        while self.text == "@":
            start = self.start
            self.advance()
            name = self.text
            if self.kind != "word" or "." in name:  # type: ignore[operator]
                raise NotAccepted("attribute name")
            self.advance()
            self.expect("(")
            args: List[str] = []
            if self.text != ")":
                args.append(self.str_value())
                while self.text == ",":
                    self.advance()
                    args.append(self.str_value())
            self.expect(")")
            out.append(ast.Attr(name, tuple(args), span=self.span(start)))  # type: ignore[arg-type]
        return tuple(out)

    def closing(self) -> int:
        """'}' and an optional ';': the end offset of the declaration."""
        end = self.expect("}") + 1
        if self.text == ";":
            end = self.expect(";") + 1
        return end

    def entity(self, start: int, attrs: Tuple[ast.Attr, ...]) -> ast.Entity:
        self.advance()
        name = self.ident()
        nodes: List[ast.Ident] = []
        if self.text == ":":
            nodes.append(self.node_name(self.end))
            while self.text == ",":
                nodes.append(self.node_name(self.end))
        if self.text == ";":
            self.advance()
        self.expect("{")
        self.expect("rules")
        self.expect(":")
        rules: List[ast.Rule] = []
        while self.text != "}":
            rules.append(self.rule())
        return ast.Entity(name, tuple(nodes), tuple(rules), span=self.span(start, self.closing()), attrs=attrs)

    def node_name(self, pos: int) -> ast.Ident:
        name, at = self.relex(_NODE_NAME, pos)
        return ast.Ident(name, span=self.span(at))

    def rule(self) -> ast.Rule:
        start = self.start
        attrs = self.attrs()
        name = self.ident()
        self.expect(":")
        expr = self.expr()
        return ast.Rule(name, expr, span=self.span(start, self.expect(";") + 1), attrs=attrs)

    def behaviour(self, start: int, attrs: Tuple[ast.Attr, ...]) -> ast.Behaviour:
        label = None
        if self.text != "if":
            label = self.ident()
            self.expect(":")
            if self.text != "if":
                raise NotAccepted("if")
        self.advance()
        self.expect("(")
        cond = self.expr()
        self.expect(")")
        self.expect("then")
        self.expect("{")
        calls: List[ast.ActionCall] = []
        while self.text != "}":
            calls.append(self.action_call())
        return ast.Behaviour(cond, tuple(calls), span=self.span(start, self.closing()), name=label, attrs=attrs)

    def action_call(self) -> ast.ActionCall:
        start = self.start
        name = self.ident()
        args: Tuple[Any, ...] = ()
        if self.text == "(":
            self.advance()
            args = self.exprs()
        return ast.ActionCall(name, args, span=self.span(start, self.expect(";") + 1))

    # ---- expressions -----------------------------------------------------------------
    def exprs(self) -> Tuple[Any, ...]:
        """[expr (',' expr)*] ')' after a '(' (call and action arguments)."""
        args: List[Any] = []
        if self.text != ")":
            args.append(self.expr())
            while self.text == ",":
                self.advance()
                args.append(self.expr())
        self.expect(")")
        return tuple(args)

    def expr(self) -> Any:
        """An operator expression, then `for T` / `within T` postfixes, left to right (§10)."""
        expr = self.climb(0)
        while self.text == "for" or self.text == "within":
            node = ast.For if self.text == "for" else ast.Within
            start = self.start
            self.advance()
            duration = self.unary()
            if self.text == "and" or self.text == "or":  # pyparsing's hint to add parentheses
                raise NotAccepted("and/or after a duration")
            expr = node(expr, duration, span=self.span(start))
        return expr

    def enter(self, cost: int) -> None:
        self.depth += cost
        if self.depth > self.max_depth:
            raise NotAccepted("nested deeply")

    def climb(self, min_prec: int) -> Any:
        """grammar._Climb over the token stream: the same tree, the same refusals."""
        if self.text == "not":
            if min_prec > _NOT_PREC:
                raise NotAccepted("not")
            start = self.start
            self.advance()
            self.enter(_NOT)
            left = ast.Unary("not", self.climb(_NOT_PREC), span=self.span(start))
            self.depth -= _NOT
        else:
            left = self.unary()
        while True:
            op = self.text
            prec = _BIN_PREC.get(op)  # type: ignore[arg-type]
            if prec is None or prec < min_prec:
                return left
            start = self.start
            self.advance()
            right = self.climb(prec + 1)
            left = ast.Binary(op, left, right, span=self.span(start))
            if prec == 5 and _BIN_PREC.get(self.text) == 5:  # type: ignore[arg-type]
                raise NotAccepted("chained comparison")

    def unary(self) -> Any:
        if self.text != "-":
            return self.primary()
        start = self.start
        self.advance()
        self.enter(_MINUS)
        operand = self.unary()
        self.depth -= _MINUS
        if isinstance(operand, ast.Num):
            return ast.Num(-operand.value, operand.unit, span=self.span(start), text=operand.text)
        return ast.Unary("-", operand, span=self.span(start))

    def primary(self) -> Any:
        kind, text, start = self.kind, self.text, self.start
        if kind == "word":
            if text == "true" or text == "false":
                self.advance()
                return ast.Bool(text == "true", span=self.span(start))
            if text == "topic":
                name, _ = self.relex(_TOPIC_NAME, self.end)
                return _topic(self.s, start, (text, name))
            if text == "node":
                name, _ = self.relex(_NODE_NAME, self.end)
                return ast.NodeRef(name, span=self.span(start))
            parts = text.split(".")  # type: ignore[union-attr]
            for p in parts:
                if p in KEYWORDS:
                    raise NotAccepted("keyword")
            self.advance()
            if self.text != "(":
                return ast.Name(tuple(parts), span=self.span(start))
            if len(parts) > 1:
                raise NotAccepted("call of a dotted name")
            self.advance()
            self.enter(_CALL)
            args = self.exprs()
            self.depth -= _CALL
            return ast.Call(text, args, span=self.span(start))  # type: ignore[arg-type]
        if kind == "num":
            toks = (text,) if self.unit is None else (text, self.unit)
            self.advance()
            return _number(self.s, start, toks)
        if kind == "str":
            node = _string(self.s, start, (text,))
            self.advance()
            return node
        if text == "(":
            self.advance()
            self.enter(_PAREN)
            inner = self.expr()
            if self.text == ",":
                self.advance()
                inner = ast.Pair(inner, self.expr(), span=self.span(start))
            self.expect(")")
            self.depth -= _PAREN
            return inner
        raise NotAccepted("expression")


def accept(text: str, source: Source) -> Optional[Tuple[ast.Decl, ...]]:
    """The declarations of a comment-stripped text, or None when this parser leaves it to pyparsing.

    Called by grammar.parse_source, which holds the grammar's lock and context (for the spans of
    the shared token conversions).
    """
    try:
        return _Parser(text, source).spec()
    except Exception:  # NotAccepted, RecursionError, a conversion's error: pyparsing decides
        return None


def parse_fast(source: Source) -> Optional[ast.Spec]:
    """The Spec of source by this parser alone, or None where it leaves the text to pyparsing (for
    tests and measurements; grammar.parse_source is the entry point)."""
    from . import grammar

    with grammar._LOCK:
        grammar._ctx.source = source
        try:
            text, comments = grammar._strip_comments(source.text)
            decls = accept(text, source)
        except grammar._UnterminatedComment:
            return None
        finally:
            grammar._ctx.source = None
    return None if decls is None else ast.Spec(decls, tuple(comments), file=source.name)


__all__: Tuple[str, ...] = ("NotAccepted", "accept", "parse_fast")
