"""Property tests of the front end: no input makes it raise anything but SpecError, and the
pretty-printer round-trips on generated specs."""
import glob
import os

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rubass.lang import SpecError, ast, check_text, format_spec, parse_text
from rubass.lang.grammar import FUNCTIONS, KEYWORDS
from rubass.lang.library import parse_library
from rubass.lang.source import Source
from rubass.lang.sourcefile import decode_source

from conftest import ROOT

CONFIGS = [open(p, encoding="utf-8").read() for p in sorted(glob.glob(os.path.join(ROOT, "config", "*.rbs")))]
SPEC_NAME = os.path.join(ROOT, "config", "fuzz.rbs")
TOKENS = ["(", ")", "{", "}", ";", ":", ",", ".", "for", "and", "or", "not", "topic", "node", "if", "then",
          "entity", "rules", "const", "import", "action", "primitive", "1", "0.4 s", "m/s", "%", "\"", "//",
          "/*", "*/", "<", "==", "-", "/x", "age(", "frequency(", "base", "\n", "[", "]", "[-1]", "\\"]
CHECK = settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def only_spec_errors(text):
    try:
        check_text(text, SPEC_NAME)
    except SpecError as exc:
        assert exc.diagnostics and all(d.message for d in exc.diagnostics)
        exc.render()


@CHECK
@given(st.text(max_size=300))
def test_random_text(text):
    only_spec_errors(text)


@CHECK
@given(st.binary(max_size=200))
def test_random_bytes(data):
    src, diag = decode_source("x.rbs", data)
    assert (src is None) != (diag is None)
    if src is not None:
        only_spec_errors(src.text)


@st.composite
def mutated(draw):
    text = draw(st.sampled_from(CONFIGS))
    for _ in range(draw(st.integers(1, 4))):
        pos = draw(st.integers(0, len(text)))
        kind = draw(st.sampled_from(["delete", "insert", "token", "dup"]))
        if kind == "delete":
            text = text[:pos] + text[pos + draw(st.integers(1, 30)):]
        elif kind == "insert":
            text = text[:pos] + draw(st.text(max_size=5)) + text[pos:]
        elif kind == "token":
            text = text[:pos] + " " + draw(st.sampled_from(TOKENS)) + " " + text[pos:]
        else:
            end = min(len(text), pos + draw(st.integers(1, 80)))
            text = text[:pos] + text[pos:end] + text[pos:]
    return text


@CHECK
@given(mutated())
def test_mutated_specs(text):
    only_spec_errors(text)


@CHECK
@given(st.text(max_size=300) | st.sampled_from(["actions:\n  s: {plugin: serial, port: [1], baud: -3}\n",
                                                 "actions: !!python/object:os.system {}\n",
                                                 "actions:\n  a: &x [*x]\n", "{{{{", "actions:\n  1: 2\n"]))
def test_random_libraries(text):
    actions, diags = parse_library(Source("lib.yaml", text))
    assert isinstance(actions, dict) and all(d.message for d in diags)


# ---- generated valid programs --------------------------------------------------------
IDENT = st.from_regex(r"[a-z_][a-z0-9_]{0,6}", fullmatch=True).filter(lambda s: s not in KEYWORDS)
GRAPH = st.from_regex(r"/[a-z][a-z0-9_]{0,4}(/[a-z][a-z0-9_]{0,4})?", fullmatch=True)
UNITS = st.sampled_from([None, None, "s", "ms", "m/s", "deg/s", "%", "MB", "Hz", "m"])
NUMBER = st.floats(min_value=0, max_value=1e9, allow_nan=False) | st.integers(0, 10 ** 6).map(float)


def leaves():
    return st.one_of(
        st.builds(ast.Num, NUMBER, UNITS),
        st.builds(ast.Bool, st.booleans()),
        st.builds(ast.Str, st.text(st.characters(blacklist_categories=("Cs",), blacklist_characters="\n"), max_size=5)),
        st.builds(lambda a, b: ast.Name((a,) if b is None else (a, b)), IDENT, st.none() | IDENT),
        st.builds(ast.TopicRef, GRAPH, st.lists(IDENT | st.integers(-3, 5), max_size=3).map(tuple)),
    )


def extend(children):
    return st.one_of(
        st.builds(ast.Unary, st.just("not"), children),
        st.builds(ast.Unary, st.just("-"), children.filter(lambda e: not isinstance(e, ast.Num))),
        st.builds(ast.Binary, st.sampled_from(["+", "-", "*", "/", "<", ">=", "==", "and", "or"]), children, children)
        .filter(lambda b: not (b.op in ("<", ">=", "==") and any(
            isinstance(x, ast.Binary) and x.op in ("<", ">=", "==") for x in (b.left, b.right)))),
        st.builds(ast.For, children, st.builds(ast.Num, NUMBER, st.just("s"))),
        st.builds(ast.Call, st.sampled_from(sorted(FUNCTIONS)), st.lists(children, max_size=3).map(tuple)),
    )


EXPR = st.recursive(leaves(), extend, max_leaves=12)


@st.composite
def specs(draw):
    decls = []
    for _ in range(draw(st.integers(0, 4))):
        kind = draw(st.sampled_from(["const", "entity", "if", "action", "import"]))
        if kind == "const":
            decls.append(ast.Const(ast.Ident(draw(IDENT)), draw(EXPR)))
        elif kind == "entity":
            rules = tuple(ast.Rule(ast.Ident(draw(IDENT)), draw(EXPR)) for _ in range(draw(st.integers(0, 3))))
            nodes = tuple(ast.Ident(n) for n in draw(st.lists(IDENT, max_size=2)))
            decls.append(ast.Entity(ast.Ident(draw(IDENT)), nodes, rules))
        elif kind == "if":
            calls = tuple(ast.ActionCall(ast.Ident(draw(IDENT)), tuple(draw(st.lists(leaves(), max_size=2))))
                          for _ in range(draw(st.integers(0, 2))))
            decls.append(ast.Behaviour(draw(EXPR), calls))
        elif kind == "action":
            decls.append(ast.ActionDecl(tuple(ast.Ident(n) for n in draw(st.lists(IDENT, min_size=1, max_size=3)))))
        else:
            decls.append(ast.Import(draw(st.text(st.characters(blacklist_categories=("Cs",),
                                                                 blacklist_characters="\n"), max_size=10))))
    return ast.Spec(tuple(decls))


def normal(e):
    """The AST the parser gives for e: '-' of a number is folded into the number."""
    if isinstance(e, ast.Unary):
        inner = normal(e.operand)
        if e.op == "-" and isinstance(inner, ast.Num):
            return ast.Num(-inner.value, inner.unit)
        return ast.Unary(e.op, inner)
    if isinstance(e, ast.Binary):
        return ast.Binary(e.op, normal(e.left), normal(e.right))
    if isinstance(e, ast.For):
        return ast.For(normal(e.operand), normal(e.duration))
    if isinstance(e, ast.Call):
        return ast.Call(e.func, tuple(normal(a) for a in e.args))
    return e


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(specs())
def test_pretty_printer_round_trips(spec):
    text = format_spec(spec)
    parsed = parse_text(text)
    assert format_spec(parsed) == text
    again = parse_text(format_spec(parsed))
    assert again == parsed


@settings(max_examples=300, deadline=None)
@given(EXPR)
def test_expression_round_trip_is_exact(expr):
    spec = ast.Spec((ast.Const(ast.Ident("x"), expr),))
    parsed = parse_text(format_spec(spec))
    assert parsed.decls[0].expr == normal(expr)
