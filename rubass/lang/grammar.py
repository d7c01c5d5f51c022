"""The pyparsing grammar of RuBaSS (LANGUAGE.md §2–4); parse actions build the AST.

Only camelCase pyparsing names are used: they exist in pyparsing 2.4 (ROS Noetic) and 3.x.
"""
from __future__ import annotations

import re
import threading
from typing import Any, Callable, List, Optional, Tuple

import pyparsing as pp

from . import ast
from .errors import Diagnostic, SpecError
from .source import Source, SourceSet, Span

KEYWORDS = frozenset(
    "action primitive entity rules if then topic node and or not for true false const import within".split()
)
FUNCTIONS = frozenset(
    "abs sqrt min max hypot len frequency age alive cpu memory "  # version 1
    "rate stamp_age any all count polygon inside distance active latch".split()  # version 2 (§10–14)
)

_IDENT_RE = r"[A-Za-z_][A-Za-z0-9_]*"
_GRAPH_RE = rf"~?/?{_IDENT_RE}(?:/{_IDENT_RE})*"
_INDEX_RE = r"\[\s*-?\d+\s*\]|\[\s*\*\s*\]|\[\s*-?\d*\s*:\s*-?\d*\s*\]"
_INDEX_RE += r"|\[[^\[\]\n]{0,40}\]"  # any other '[…]' on one line: an ast.BadIndex, the checker's error
_PATH_RE = rf"(?:\.{_IDENT_RE}|{_INDEX_RE})*"
_NUM_RE = r"(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?"
_UNIT_RE = r"%|[A-Za-z]+(?:/[A-Za-z]+(?:\^[0-9]+)?)?(?![A-Za-z0-9_])"


class _Op:
    """An operator token with its offset, so a Binary can point at its operator."""

    __slots__ = ("text", "loc")

    def __init__(self, text: str, loc: int) -> None:
        self.text, self.loc = text, loc


class _Ctx(threading.local):
    source: Optional[Source] = None


_ctx = _Ctx()


def _span(loc: int, end: int = -1) -> Span:
    assert _ctx.source is not None
    return _ctx.source.span(loc, end)


def _fail(s: str, loc: int, msg: str) -> None:
    raise pp.ParseFatalException(s, loc, msg)


def _kw(word: str) -> pp.ParserElement:
    return pp.Keyword(word).setName(f"'{word}'")


def _lit(text: str) -> pp.ParserElement:
    return pp.Literal(text).setName(f"'{text}'")


def _seq(*parts: pp.ParserElement, commit_after: int = 1) -> pp.ParserElement:
    """parts in order; once the first commit_after parts matched, a failure is a syntax error.

    An explicit flat And with pyparsing's error stop, rather than the '-' operator, whose
    nested Ands are not always flattened (and then lose the stop).
    """
    items = list(parts[:commit_after]) + [pp.And._ErrorStop()] + list(parts[commit_after:])
    return pp.And(items)


def _action(el: pp.ParserElement, fn: Callable[[str, int, Any], Any]) -> pp.ParserElement:
    return el.addParseAction(fn)


_BIN_PREC = {"or": 2, "and": 3, "<": 5, "<=": 5, ">": 5, ">=": 5, "==": 5, "!=": 5,
             "+": 6, "-": 6, "*": 7, "/": 7}
_NOT_PREC = 4


class _Climb:
    """Precedence climbing over a flat [not…] operand (op [not…] operand)* token list.

    One flat pyparsing sequence instead of a grammar level per precedence: a third of the
    parse time of a large spec.
    """

    def __init__(self, s: str, items: List[Any]) -> None:
        self.s, self.items, self.i = s, items, 0

    def peek(self) -> Any:
        return self.items[self.i] if self.i < len(self.items) else None

    def expr(self, min_prec: int) -> Any:
        tok = self.peek()
        if isinstance(tok, _Op) and tok.text == "not":
            if min_prec > _NOT_PREC:
                _fail(self.s, tok.loc, "'not' binds less tightly than comparisons and arithmetic: "
                                       "put it in parentheses, e.g. '(not a)'")
            self.i += 1
            left: Any = ast.Unary("not", self.expr(_NOT_PREC), span=_span(tok.loc))
        else:
            left = tok
            self.i += 1
        while True:
            op = self.peek()
            if not isinstance(op, _Op) or _BIN_PREC[op.text] < min_prec:
                return left
            prec = _BIN_PREC[op.text]
            self.i += 1
            right = self.expr(prec + 1)
            left = ast.Binary(op.text, left, right, span=_span(op.loc))
            nxt = self.peek()
            if prec == 5 and isinstance(nxt, _Op) and _BIN_PREC.get(nxt.text) == 5:
                _fail(self.s, nxt.loc, f"comparisons cannot be chained: write '(a {op.text} b) and "
                                       f"(b {nxt.text} c)' instead of 'a {op.text} b {nxt.text} c'")


def _climb(s: str, loc: int, toks: Any) -> Any:
    return _Climb(s, list(toks)).expr(0)


def _unary(s: str, loc: int, toks: Any) -> Any:
    op, operand = toks[0], toks[1]
    if op.text == "-" and isinstance(operand, ast.Num):
        return ast.Num(-operand.value, operand.unit, span=_span(op.loc), text=operand.text)
    return ast.Unary(op.text, operand, span=_span(op.loc))


def _for(s: str, loc: int, toks: Any) -> Any:
    """`E for T within U …`: postfix, applied left to right (§10)."""
    items = list(toks)
    expr = items[0]
    for i in range(1, len(items), 2):
        node = ast.For if items[i].text == "for" else ast.Within
        expr = node(expr, items[i + 1], span=_span(items[i].loc))
    return expr


def _number(s: str, loc: int, toks: Any) -> Any:
    """A number; one too large for a float (1e999) is infinite here, an error of the checker's."""
    unit = toks[1] if len(toks) > 1 else None
    return ast.Num(float(toks[0]), unit, span=_span(loc), text=toks[0])


_ESCAPES = {'"': '"', "\\": "\\"}


def _string(s: str, loc: int, toks: Any) -> Any:
    body = toks[0][1:-1]
    out: List[str] = []
    i = 0
    while i < len(body):
        ch = body[i]
        if ch == "\\":
            nxt = body[i + 1] if i + 1 < len(body) else ""
            if nxt not in _ESCAPES:
                _fail(s, loc + 1 + i, f"unknown escape '\\{nxt}' in string (only \\\" and \\\\)")
            out.append(_ESCAPES[nxt])
            i += 2
        else:
            out.append(ch)
            i += 1
    return ast.Str("".join(out), span=_span(loc))


def _topic(s: str, loc: int, toks: Any) -> Any:
    text = toks[1]
    m = re.match(_GRAPH_RE, text)
    assert m is not None
    path: List[ast.PathElem] = []
    for part in re.finditer(rf"\.({_IDENT_RE})|\[([^\]]*)\]", text[m.end():]):
        if part.group(1):
            path.append(part.group(1))
            continue
        inner = re.sub(r"\s", "", part.group(2))
        if inner == "*" or re.fullmatch(r"(?:-?\d+)?:(?:-?\d+)?", inner):  # a second slice is the checker's error
            a, _, b = inner.partition(":") if inner != "*" else ("", "", "")
            path.append(ast.Slice(int(a) if a else None, int(b) if b else None))
        elif re.fullmatch(r"-?\d+", inner):
            path.append(int(inner))
        else:  # where the '[' is: after 'topic' and the spaces before the name
            at = s.find(text, loc) + m.end() + part.start()
            path.append(ast.BadIndex(part.group(0), span=_span(at, at + len(part.group(0)))))
    return ast.TopicRef(m.group(0), tuple(path), span=_span(loc))


def _name(s: str, loc: int, toks: Any) -> Any:
    parts = tuple(toks[0].split("."))
    for p in parts:
        if p in KEYWORDS:
            _fail(s, loc, f"'{p}' is a keyword and cannot be used as a name")
    return ast.Name(parts, span=_span(loc))


def _ident(s: str, loc: int, toks: Any) -> Any:
    return ast.Ident(toks[0], span=_span(loc))


def _not_keyword(s: str, loc: int, toks: Any) -> bool:
    return toks[0] not in KEYWORDS


_LEX = re.compile(r'"(?:[^"\\\n]|\\.)*"|//[^\n]*|/\*[\s\S]*?\*/|/\*')


def _strip_comments(text: str) -> Tuple[str, List[ast.Comment]]:
    """Blank out comments (same length, newlines kept) and collect them; strings are skipped.

    Done before parsing rather than with pyparsing's ignore(), which tries the comment pattern
    before every token and was 40 % of the parse time.
    """
    comments: List[ast.Comment] = []
    pieces: List[str] = []
    last = 0
    for m in _LEX.finditer(text):
        tok = m.group(0)
        if tok.startswith('"'):
            continue
        if tok == "/*":  # the lazy alternative found no closing '*/'
            raise _UnterminatedComment(m.start())
        start = m.start()
        line_start = text.rfind("\n", 0, start) + 1
        own_line = not text[line_start:start].strip()
        comments.append(ast.Comment(tok, own_line, span=_span(start, m.end())))
        pieces.append(text[last:start])
        pieces.append(re.sub(r"[^\n]", " ", tok))
        last = m.end()
    pieces.append(text[last:])
    return "".join(pieces), comments


class _UnterminatedComment(Exception):
    def __init__(self, loc: int) -> None:
        super().__init__(loc)
        self.loc = loc


def _loc_token(text: str) -> pp.ParserElement:
    """A punctuation token that yields its offset, to give statements an end position."""
    return _action(_lit(text), lambda s, loc, t: [_Op(text, loc)])


_STATEMENTS = ("if", "entity", "const", "action", "import")  # the words a top-level statement starts with


def _build() -> pp.ParserElement:
    LPAR, RPAR = (pp.Suppress(_lit(c)).setName(f"'{c}'") for c in "()")
    SEMI = _loc_token(";").setName("';'")
    LBRACE, RBRACE = pp.Suppress(_lit("{")).setName("'{'"), _loc_token("}")
    COLON = pp.Suppress(_lit(":")).setName("':'")

    def keyword_as_name(s: str, loc: int, toks: Any) -> None:
        if toks[0] in KEYWORDS:
            hint = ""
            if toks[0] in _STATEMENTS and not s[s.rfind("\n", 0, loc) + 1:loc].strip():
                hint = f" (a statement cannot start inside an entity: is a '}}' missing before this '{toks[0]}'?)"
            _fail(s, loc, f"'{toks[0]}' is a keyword and cannot be used as a name{hint}")

    ident_node = _action(_action(pp.Regex(_IDENT_RE).setName("name"), keyword_as_name), _ident)

    def op(*texts: str) -> pp.ParserElement:
        alts = [(_kw(t) if t.isalpha() else _lit(t)) for t in texts]
        el = alts[0]
        for a in alts[1:]:
            el = el | a
        return _action(el, lambda s, loc, t: [_Op(t[0], loc)])

    number = _action(
        pp.Regex(_NUM_RE).setName("number")
        + pp.Optional(pp.Regex(_UNIT_RE).setName("unit").addCondition(_not_keyword)),
        _number,
    )
    string = (
        _action(pp.Regex(r'"(?:[^"\\\n]|\\.)*"'), _string)
        | _action(pp.Regex(r'"[^\n]*'), lambda s, loc, t: _fail(s, loc, "unterminated string"))
    ).setName("string")
    true = _action(_kw("true"), lambda s, loc, t: ast.Bool(True, span=_span(loc)))
    false = _action(_kw("false"), lambda s, loc, t: ast.Bool(False, span=_span(loc)))
    topic = _action(
        _seq(_kw("topic"), pp.Regex(_GRAPH_RE + _PATH_RE).setName("topic name")), _topic
    )
    node = _action(
        _seq(_kw("node"), pp.Regex(_GRAPH_RE).setName("node name")),
        lambda s, loc, t: ast.NodeRef(t[1], span=_span(loc)),
    )
    expr = pp.Forward().setName("expression")
    call = _action(
        _seq(pp.Regex(_IDENT_RE), pp.FollowedBy(_lit("(")), LPAR,
             pp.Optional(pp.delimitedList(expr)), RPAR, commit_after=3),
        lambda s, loc, t: ast.Call(t[0], tuple(t[1:]), span=_span(loc)),
    )
    name = _action(pp.Regex(rf"{_IDENT_RE}(?:\.{_IDENT_RE})?").addCondition(_not_keyword), _name)

    def paren(s: str, loc: int, toks: Any) -> Any:
        if len(toks) == 1:
            return toks[0]
        return ast.Pair(toks[0], toks[1], span=_span(loc))

    comma = pp.Suppress(_lit(","))
    parens = _action(_seq(LPAR, expr, pp.Optional(comma + expr), RPAR), paren)
    primary = (
        true | false | number | string | topic | node | call | name | parens
    ).setName("expression")
    unary = pp.Forward().setName("expression")
    unary <<= (_action(op("-") + unary, _unary) | primary).setName("expression")
    nots = pp.ZeroOrMore(op("not"))
    binop = _action(pp.Regex(r"<=|>=|==|!=|<|>|\+|-|\*|/|(?:and|or)(?![A-Za-z0-9_])").setName("operator"),
                    lambda s, loc, t: [_Op(t[0], loc)])
    operand = nots + unary
    flat = _action(operand + pp.ZeroOrMore(_seq(binop, operand)), _climb)
    def hint(word: str) -> pp.ParserElement:
        return _action(
            op("and", "or"),
            lambda s, loc, t: _fail(
                s, loc, f"'{word}' applies to everything on its left; to combine its result, put it in "
                        f"parentheses: '(A {word} T) {t[0].text} B'"),
        )

    duration = unary.copy().setName("duration (e.g. 0.4 s)")
    postfix = _seq(op("for"), duration, pp.Optional(hint("for"))) | \
        _seq(op("within"), duration, pp.Optional(hint("within")))
    for_expr = _action(flat + pp.ZeroOrMore(postfix), _for)
    expr <<= for_expr

    def stmt(el: pp.ParserElement, fn: Callable[[Span, List[Any]], Any]) -> pp.ParserElement:
        def act(s: str, loc: int, toks: Any) -> Any:
            items = list(toks)
            end = loc
            for it in items:
                if isinstance(it, _Op) and it.text in ";}":
                    end = max(end, it.loc + 1)
            items = [i for i in items if not isinstance(i, (_Op, str))]  # punctuation, keywords
            return fn(_span(loc, end), items)
        return _action(el, act)

    import_stmt = stmt(
        _seq(_kw("import"), string, SEMI), lambda sp, t: ast.Import(t[0].value, span=sp))
    action_decl = stmt(
        _seq(_kw("action"), _kw("primitive"), pp.delimitedList(ident_node), SEMI),
        lambda sp, t: ast.ActionDecl(tuple(t), span=sp))
    const_decl = stmt(
        _seq(_kw("const"), ident_node, pp.Suppress(_lit("=")).setName("'='"), expr, SEMI),
        lambda sp, t: ast.Const(t[0], t[1], span=sp))
    attr = _action(
        _seq(_lit("@"), pp.Regex(_IDENT_RE).setName("attribute name"), LPAR,
             pp.Optional(pp.delimitedList(string)), RPAR.copy().setName("')' or a string argument")),
        lambda s, loc, t: ast.Attr(t[1], tuple(a.value for a in t[2:]), span=_span(loc)))
    attrs = pp.Group(pp.ZeroOrMore(attr))
    rule = stmt(attrs + _seq(ident_node, COLON, expr, SEMI, commit_after=2),
                lambda sp, t: ast.Rule(t[1], t[2], span=sp, attrs=tuple(t[0])))
    node_name = _action(pp.Regex(_GRAPH_RE).setName("node name"), _ident)
    header = pp.Group(pp.Optional(_seq(COLON, pp.delimitedList(node_name))))
    entity = stmt(
        attrs + _seq(_kw("entity"), ident_node, header, pp.Optional(pp.Suppress(_lit(";"))),
                     LBRACE, pp.Suppress(_kw("rules")), COLON, pp.Group(pp.ZeroOrMore(rule)),
                     RBRACE.copy().setName("'}' or a rule 'name: expression;'"), pp.Optional(SEMI)),
        lambda sp, t: ast.Entity(t[1], tuple(t[2]), tuple(t[3]), span=sp, attrs=tuple(t[0])))
    args = pp.Group(pp.Optional(_seq(LPAR, pp.Optional(pp.delimitedList(expr)), RPAR)))
    action_call = stmt(
        _seq(ident_node, args, SEMI, commit_after=2), lambda sp, t: ast.ActionCall(t[0], tuple(t[1]), span=sp))
    label_name = _action(pp.Regex(_IDENT_RE).setName("name").addCondition(_not_keyword), _ident)
    label = pp.Group(pp.Optional(label_name + COLON + pp.FollowedBy(_kw("if"))))
    behaviour = stmt(
        attrs + label + _seq(_kw("if"), LPAR, expr, RPAR, _kw("then"), LBRACE, pp.Group(pp.ZeroOrMore(action_call)),
                             RBRACE.copy().setName("'}' or an action 'name;'"), pp.Optional(SEMI)),
        lambda sp, t: ast.Behaviour(t[2], tuple(t[3]), span=sp, name=t[1][0] if len(t[1]) else None,
                                    attrs=tuple(t[0])))
    decl = import_stmt | action_decl | const_decl | entity | behaviour
    end = pp.StringEnd().setName("a declaration (import, action, const, entity or if)")
    spec = _seq(pp.ZeroOrMore(decl), end)
    return spec


_GRAMMAR: Optional[pp.ParserElement] = None
_LOCK = threading.Lock()


def _found(text: str, loc: int) -> str:
    if loc >= len(text):
        return "end of file"
    m = re.match(r"\S{1,20}", text[loc:])
    return f"'{m.group(0)}'" if m else "end of file"


_UNIT_CHARACTERS = {"\u00b0": "write degC for a temperature, deg for an angle",
                    "\u00b5": "write us for microseconds", "\u03bc": "write us for microseconds"}


def _unit_character(text: str, loc: int) -> str:
    """A hint when a unit is written with a character the language has none of ('°C', 'µs')."""
    m = re.match(r"\s*(\S)", text[loc:])
    hint = _UNIT_CHARACTERS.get(m.group(1)) if m else None
    return f" ('{m.group(1)}' is no character of the language: {hint})" if m and hint else ""


def _bad_index(text: str, loc: int) -> Optional[str]:
    """The message for a '[' after a field path that is no index, slice or [*] (None otherwise)."""
    if not text.startswith("[", loc) or not re.search(rf"\btopic\s+{_GRAPH_RE}{_PATH_RE}\Z", text[max(0, loc - 300):loc]):
        return None  # only after a topic's field path
    m = re.match(r"\[[^\]\n]{0,20}\]?", text[loc:])
    bad = m.group(0) if m else "["
    return bad_index_message(bad)


def bad_index_message(bad: str) -> str:
    """The error for `bad` ('[0.5]') written as an index of a field path."""
    return (f"'{bad}' is not an index: write an integer ([0], [-1]), a slice of integers ([0:90], [-90:]) "
            "or [*] for the whole array")


def parse_source(source: Source, fast: bool = True) -> ast.Spec:
    """Parse one source file into a Spec; raises SpecError for a syntax error.

    The fast parser (fastparse.py) is tried first; a text it does not accept is parsed by this
    pyparsing grammar, the reference, which reports every syntax error. fast=False: pyparsing only.
    """
    global _GRAMMAR
    from . import fastparse  # it imports this module's tables

    with _LOCK:
        if _GRAMMAR is None:
            _GRAMMAR = _build().parseWithTabs()
        _ctx.source = source
        try:
            text, comments = _strip_comments(source.text)
            toks = fastparse.accept(text, source) if fast else None
            if toks is None:
                toks = _GRAMMAR.parseString(text, parseAll=True)
        except _UnterminatedComment as exc:
            raise _error(source, exc.loc, "unterminated comment '/*'") from None
        except pp.ParseBaseException as exc:
            msg = exc.msg
            if msg.startswith("Expected "):
                msg = _bad_index(text, exc.loc) or f"expected {msg[len('Expected '):]}, found {_found(text, exc.loc)}" \
                    + _unit_character(text, exc.loc)
            raise _error(source, exc.loc, msg) from None
        except RecursionError:
            loc, depth = _deepest(text)
            unary = re.search(r"(?:\bnot\b\s*|-\s*){40,}", text)
            if unary is not None and depth < 40:
                raise _error(source, unary.start(), "expressions are nested too deeply to parse (a long run of "
                                                    "'not' or '-' here; two cancel out: remove pairs)") from None
            raise _error(source, loc, f"expressions are nested too deeply to parse ({depth} parentheses "
                                      "deep here; about 50 parse: flatten it, and/or chains of any length "
                                      "need no parentheses)") from None
        finally:
            _ctx.source = None
    return ast.Spec(tuple(toks), tuple(comments), file=source.name)


def _deepest(text: str) -> Tuple[int, int]:
    """The offset of the '(' where nesting is deepest, and that depth (strings skipped)."""
    depth = best = 0
    where = 0
    for m in re.finditer(r'"(?:[^"\\\n]|\\.)*"|[()]', text):
        tok = m.group(0)
        if tok == "(":
            depth += 1
            if depth > best:
                best, where = depth, m.start()
        elif tok == ")":
            depth = max(0, depth - 1)
    return where, best


def _error(source: Source, loc: int, msg: str) -> SpecError:
    sources = SourceSet()
    sources.add(source)
    return SpecError([Diagnostic(source.span(loc), msg)], sources)


def parse_text(text: str, name: str = "<string>") -> ast.Spec:
    """Parse spec text (for tests and tools); raises SpecError."""
    return parse_source(Source(name, text))


__all__: Tuple[str, ...] = ("KEYWORDS", "FUNCTIONS", "parse_source", "parse_text")
