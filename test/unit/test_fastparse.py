"""The fast parser (rubass/lang/fastparse.py) against the pyparsing reference (grammar.py).

The property that keeps them one language: whenever the fast parser accepts a text, pyparsing
accepts it too and builds the same tree, spans and comments included (== ignores spans, so the
trees are walked field by field). Where the fast parser declines, parse_source falls back to
pyparsing, so error messages are pyparsing's, unchanged.
"""
import dataclasses
import glob
import os
import re

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from rubass.lang import SpecError
from rubass.lang.fastparse import parse_fast
from rubass.lang.grammar import FUNCTIONS, KEYWORDS, parse_source
from rubass.lang.source import Source

from conftest import ROOT, SHARED

CHECK = settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def same_tree(ref, fast, path="spec"):
    """Equal type and fields, spans, comments and file names included."""
    assert type(ref) is type(fast), f"{path}: {type(ref).__name__} != {type(fast).__name__}"
    if dataclasses.is_dataclass(ref):
        for f in dataclasses.fields(ref):
            same_tree(getattr(ref, f.name), getattr(fast, f.name), f"{path}.{f.name}")
    elif isinstance(ref, tuple):
        assert len(ref) == len(fast), f"{path}: {len(ref)} != {len(fast)} items"
        for i, (a, b) in enumerate(zip(ref, fast)):
            same_tree(a, b, f"{path}[{i}]")
    else:
        assert ref == fast and repr(ref) == repr(fast), f"{path}: {ref!r} != {fast!r}"


def compare(text, name="t.rbs"):
    """The property; returns (pyparsing's Spec or None, fast Spec or None)."""
    src = Source(name, text)
    fast = parse_fast(src)
    try:
        ref = parse_source(src, fast=False)
    except SpecError:
        assert fast is None, f"the fast parser accepts a text pyparsing rejects: {text!r}"
        return None, None
    if fast is not None:
        same_tree(ref, fast)
    return ref, fast


# ---- (1) every spec in the repository and every example of the contract --------------------
def _rbs_files():
    out = []
    for base, dirs, files in os.walk(ROOT):
        dirs[:] = [d for d in dirs if not d.startswith(".") and d not in ("build", "devel", "__pycache__")]
        out += [os.path.join(base, f) for f in files if f.endswith(".rbs")]
    return sorted(out)


def _md_blocks(path):
    """The RuBaSS code blocks of a Markdown file (as test_examples.py extracts them)."""
    text = open(path, encoding="utf-8").read()
    return [b for lang, b in re.findall(r"```([a-z]*)\n(.*?)```", text, re.S) if lang in ("", "rubass")]


def _corpus():
    texts = [(os.path.relpath(p, ROOT), open(p, encoding="utf-8").read()) for p in _rbs_files()]
    mds = sorted(glob.glob(os.path.join(ROOT, "docs", "*.md"))) + [os.path.join(SHARED, "spec", "LANGUAGE.md")]
    for md in mds:
        if os.path.exists(md):
            texts += [(f"{os.path.basename(md)}#{i}", b) for i, b in enumerate(_md_blocks(md))]
    return texts


CORPUS = _corpus()


def test_the_corpus_holds_the_repository_specs_and_the_contract_examples():
    names = [n for n, _ in CORPUS]
    assert sum(n.endswith(".rbs") for n in names) >= 5
    assert any(n.startswith("language.md#") or n.startswith("LANGUAGE.md#") for n in names)


@pytest.mark.parametrize("name,text", CORPUS, ids=[n for n, _ in CORPUS])
def test_corpus_parses_to_the_same_tree_spans_and_comments(name, text):
    ref, fast = compare(text, name)
    if ref is not None:  # a valid spec: the fast parser must take it (else no speed-up)
        assert fast is not None, f"the fast parser declined the valid spec {name}"


def test_the_benchmark_spec_takes_the_fast_path():
    import sys

    sys.path.insert(0, os.path.join(ROOT, "bench"))
    from parse_check import generate

    ref, fast = compare(generate(60), "bench.rbs")
    assert ref is not None and fast is not None and len(ref.decls) == 4 + 2 * 6


# ---- (2) generated valid specs ----------------------------------------------------------
SEP = st.sampled_from([" ", " ", " ", "  ", "\n", "\t", "\r\n", " /* c */ ", " // c\n", "\n\n  "])
SEP0 = st.sampled_from(["", "", " ", "\n", "\t"])
IDENT = st.from_regex(r"[a-z_][a-z0-9_]{0,5}", fullmatch=True).filter(lambda s: s not in KEYWORDS)
WORD = st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,4}", fullmatch=True)  # keywords included
GRAPH = st.from_regex(r"~?/?[a-z][a-z0-9_]{0,3}(/[a-z][a-z0-9_]{0,3})?", fullmatch=True)
INDEX = st.sampled_from(["[0]", "[-1]", "[ 2 ]", "[*]", "[ * ]", "[0:90]", "[:3]", "[-2:]", "[ 1 : -1 ]", "[:]"])
PATH = st.lists(st.one_of(IDENT.map(lambda s: "." + s), INDEX), max_size=3).map("".join)
NUM = st.sampled_from(["0", "5", "1.5", ".5", "5.", "1e3", "2.5E-2", "007", "90", "1e-3", "3.0e+2"])
UNIT = st.sampled_from(["", "", "s", "ms", "m/s", "m/s^2", "%", "Hz", "deg", "MB", "x"])
STRING = st.sampled_from(['""', '"a"', '"a b"', '"\\""', '"\\\\"', '"x\\"y\\\\z"', '"SR-3"', '"tab\there"', '"é"'])
FUNC = st.sampled_from(sorted(FUNCTIONS) + ["f"])
BINOP = st.sampled_from(["+", "-", "*", "/", "<", "<=", ">", ">=", "==", "!=", "and", "or", "and", "or"])


def _leaf():
    return st.one_of(
        st.builds(lambda n, s, u: n + (s if u else "") + u, NUM, SEP0, UNIT),
        st.sampled_from(["true", "false"]),
        STRING,
        IDENT,
        st.builds(lambda a, b: f"{a}.{b}", IDENT, IDENT),
        st.builds(lambda s, g, p: f"topic{s}{g}{p}", SEP, GRAPH, PATH),
        st.builds(lambda s, g: f"node{s}{g}", SEP, GRAPH),
    )


def _extend(child):
    return st.one_of(
        st.builds(lambda a, s, o, t, b: f"{a}{s}{o}{t}{b}", child, SEP, BINOP, SEP, child),
        st.builds(lambda s, a: f"not{s}{a}", SEP, child),
        # '-not (x)' is the call not(x) to pyparsing, which the fast parser leaves to it
        st.builds(lambda s, a: f"-{s}{a}", SEP0, child.filter(lambda a: not a.startswith("not"))),
        st.builds(lambda s, a, t: f"({s}{a}{t})", SEP0, child, SEP0),
        st.builds(lambda a, b: f"({a}, {b})", child, child),
        st.builds(lambda a, s, k, t, d: f"{a}{s}{k}{t}{d}", child, SEP, st.sampled_from(["for", "within"]), SEP,
                  st.one_of(st.builds(lambda n, u: f"{n} {u}", NUM, st.sampled_from(["s", "ms"])), IDENT)),
        st.builds(lambda f, s, args: f"{f}{s}({', '.join(args)})", FUNC, SEP0, st.lists(child, max_size=3)),
    )


EXPR = st.recursive(_leaf(), _extend, max_leaves=10)
ATTRS = st.lists(st.builds(lambda n, a, s: f"@{n}({', '.join(a)}){s}", WORD, st.lists(STRING, max_size=2), SEP),
                 max_size=2).map("".join)


@st.composite
def spec_texts(draw):
    out = []
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(["import", "action", "const", "entity", "if", "if"]))
        s = draw(SEP)
        if kind == "import":
            out.append(f"import{s}{draw(STRING)}{draw(SEP0)};")
        elif kind == "action":
            out.append(f"action primitive{s}{', '.join(draw(st.lists(IDENT, min_size=1, max_size=3)))};")
        elif kind == "const":
            out.append(f"const {draw(IDENT)}{draw(SEP0)}={s}{draw(EXPR)};")
        elif kind == "entity":
            nodes = draw(st.lists(GRAPH, max_size=2))
            header = f":{s}{', '.join(nodes)}" if nodes else ""
            rules = "".join(f"{draw(SEP)}{draw(ATTRS)}{draw(IDENT)}:{draw(SEP0)}{draw(EXPR)};"
                            for _ in range(draw(st.integers(0, 3))))
            semi = draw(st.sampled_from(["", ";"]))
            out.append(f"{draw(ATTRS)}entity {draw(IDENT)}{header}{semi}{draw(SEP0)}{{{s}rules:{rules}{draw(SEP)}}}"
                       f"{draw(st.sampled_from(['', ';']))}")
        else:
            label = draw(st.one_of(st.just(""), IDENT.map(lambda n: f"{n}:{' '}")))
            calls = "".join(
                f"{draw(SEP)}{draw(IDENT)}" + draw(st.one_of(st.just(""), st.lists(EXPR, max_size=2).map(
                    lambda a: f"({', '.join(a)})"))) + ";" for _ in range(draw(st.integers(0, 2))))
            out.append(f"{draw(ATTRS)}{label}if{draw(SEP0)}({draw(EXPR)}){s}then{draw(SEP0)}{{{calls}{draw(SEP)}}}"
                       f"{draw(st.sampled_from(['', ';']))}")
    return draw(SEP0) + draw(SEP).join(out) + draw(SEP0)


@CHECK
@given(spec_texts())
@example("const x = 5 s;")
@example("entity e: /a, ~b; { rules: @id(\"R1\") r: topic /s.ranges[0:90] < 1 m within 2 s for T; } ;")
def test_generated_specs_parse_to_the_same_tree(text):
    ref, fast = compare(text)
    if ref is not None:
        assert fast is not None, f"the fast parser declined a valid generated spec: {text!r}"


def test_most_generated_specs_are_valid():
    """Guards the generator: if it produced mostly invalid text, the property would test little."""
    seen = []

    @settings(max_examples=60, derandomize=True, database=None, deadline=None,
              suppress_health_check=[HealthCheck.too_slow])
    @given(spec_texts())
    def sample(text):
        seen.append(compare(text)[0] is not None)

    sample()
    assert sum(seen) >= len(seen) // 4, f"{sum(seen)} of {len(seen)} generated specs are valid"


# ---- (3) mutated specs: whatever the fast parser accepts, pyparsing accepts the same -------
TOKENS = ["(", ")", "{", "}", ";", ":", ",", ".", "@", "=", "for", "within", "and", "or", "not", "topic", "node",
          "if", "then", "entity", "rules", "const", "import", "action", "primitive", "true", "1", "5and", "5for",
          "0.4 s", "m/s", "%", "\"", "\\", "//", "/*", "*/", "<", "==", "-", "--", "/x", "~", "[", "]", "[*]",
          "[0:1]", "age(", "e", "$", "\n", "\t", "\f", "1e999", "(a, b)"]
SEEDS = [t for _, t in CORPUS if len(t) < 6000][:40] + [
    "const x = a < b and not c or -(5 s) * 2 within 1 s for 2 s;",
    'r: @id("a") if (topic /a.b[*].c > 1 and node /n == node ~m) then { stop; warn("x\\"y", 1 + 2); };',
]


@st.composite
def mutated(draw):
    text = draw(st.sampled_from(SEEDS) | spec_texts())
    for _ in range(draw(st.integers(1, 3))):
        pos = draw(st.integers(0, len(text)))
        kind = draw(st.sampled_from(["delete", "char", "token", "swap"]))
        if kind == "delete":
            text = text[:pos] + text[pos + draw(st.integers(1, 12)):]
        elif kind == "char":
            text = text[:pos] + draw(st.characters(blacklist_categories=("Cs",))) + text[pos:]
        elif kind == "token":
            sp = draw(st.sampled_from(["", " "]))
            text = text[:pos] + sp + draw(st.sampled_from(TOKENS)) + sp + text[pos:]
        else:
            toks = re.findall(r"\s+|\w+|\W", text)
            if len(toks) > 1:
                i = draw(st.integers(0, len(toks) - 2))
                toks[i], toks[i + 1] = toks[i + 1], toks[i]
                text = "".join(toks)
    return text


@CHECK
@given(mutated())
def test_mutated_specs_never_accepted_differently(text):
    compare(text)


@pytest.mark.parametrize("text", [
    "const x = 5and true;",  # pyparsing's 'and' is a regex: it needs no space after a number
    "const x = and(1);",  # a keyword as a function name: pyparsing parses it as a call
    "const x = a for not(b);",
    "const x = (a) for 1 s for 2 s within 3 s;",
    "entity e: for { rules: }",  # node names may be keywords
    '@for("x") entity e { rules: }',  # so may attribute names
    "const x = topic /a/b.c/d;",  # a topic name, then a division
    "const x = 5 m/s2;",  # unit 'm', then '/ s2'
    "const x = 1.e3x;",
    "const x = ٣ + 1;",  # a digit of another script is a digit (\\d)
    "const x = - - - 5 s;",
    "const x = not not not a;",
])
def test_tricky_texts_parse_alike(text):
    ref, _ = compare(text)
    assert ref is not None


@pytest.mark.parametrize("text", [
    "const x = a for 5for 1 s;",  # pyparsing's Keyword needs a break before 'for'
    "const x = a.b.c;",
    "const x = a.b(1);",
    "const x = f(a,);",
    "const x = (a, b, c);",
    "entity e { rules: r: a for 1 s or b; }",
    "const x = a == not b;",
    "const x = a < b < c;",
    "const x = 1 \f+ 2;",  # a form feed is not whitespace to pyparsing
    "const x = a$;",
])
def test_bad_texts_are_left_to_pyparsing(text):
    assert parse_fast(Source("t.rbs", text)) is None
    assert compare(text) == (None, None)


@pytest.mark.parametrize("kind,make", [
    ("parens", lambda n: "const x = " + "(" * n + "1" + ")" * n + ";"),
    ("calls", lambda n: "const x = " + "abs(" * n + "1" + ")" * n + ";"),
    ("minus", lambda n: "const x = " + "- " * n + "a;"),
    ("not", lambda n: "const x = " + "not " * n + "a;"),
])
def test_deep_nesting_is_left_to_pyparsing(kind, make):
    """Shallow nesting takes the fast path; from where pyparsing may run out of stack, pyparsing decides."""
    assert parse_fast(Source("t.rbs", make(8))) is not None
    for n in (8, 30, 45, 60, 200, 1200):
        compare(make(n))
        assert outcome(make(n), fast=True) == outcome(make(n), fast=False)


def outcome(text, fast):
    try:
        return "parsed", parse_source(Source("t.rbs", text), fast=fast)
    except SpecError as exc:
        return "error", str(exc)


def test_too_deep_nesting_gives_the_same_error():
    text = "const x = " + "(" * 60 + "1" + ")" * 60 + ";"
    assert outcome(text, fast=True) == outcome(text, fast=False)
    if outcome(text, fast=False)[0] == "error":  # pyparsing 3 (2.4 recurses less per level)
        assert outcome(text, fast=True)[1].startswith(
            "t.rbs:1:70: error: expressions are nested too deeply to parse (60 parentheses deep here; about 50 "
            "parse: flatten it, and/or chains of any length need no parentheses)")


# ---- (4) errors are exactly as before ------------------------------------------------------
@pytest.mark.parametrize("text,message", [
    ("entity e { rules: r: 1 +; }", "bad.rbs:1:25: error: expected expression, found ';'"),
    ("entity e { rules: r: a < b < c; }",
     "bad.rbs:1:28: error: comparisons cannot be chained: write '(a < b) and (b < c)' instead of 'a < b < c'"),
    ("const x = 5 s\nconst y = 1;", "bad.rbs:2:1: error: expected ';', found 'const'"),
    ("entity e { rules: r: a for 1 s and b; }",
     "bad.rbs:1:31: error: 'for' applies to everything on its left; to combine its result, put it in parentheses: "
     "'(A for T) and B'"),
    ('import "a\\q";', "bad.rbs:1:10: error: unknown escape '\\q' in string (only \\\" and \\\\)"),
    ("entity for { rules: }", "bad.rbs:1:8: error: 'for' is a keyword and cannot be used as a name"),
    ("const x = 1;\n\tconst y = (2;", "bad.rbs:2:14: error: expected ')', found ';'"),
    # 1e999, two slices in one path and '[0.5]' parse: the checker reports them beside the other errors
    # (test_checker_fixes_collected.py)
    ('const s = "open', "bad.rbs:1:11: error: unterminated string"),
    ("/* never closed", "bad.rbs:1:1: error: unterminated comment '/*'"),
])
def test_syntax_errors_are_unchanged(text, message):
    with pytest.raises(SpecError) as fast:
        parse_source(Source("bad.rbs", text))
    assert str(fast.value).splitlines()[0] == message
    with pytest.raises(SpecError) as ref:
        parse_source(Source("bad.rbs", text), fast=False)
    assert str(ref.value) == str(fast.value)


def test_deep_nesting_is_left_to_pyparsing_when_the_stack_is_short_too():
    """Called with most of the stack used already, the fast parser declines sooner."""
    text = "const x = " + "(" * 12 + "1" + ")" * 12 + ";"

    def nest(n):
        return nest(n - 1) if n else parse_fast(Source("t.rbs", text))

    import sys

    from rubass.lang.fastparse import _stack_depth

    assert parse_fast(Source("t.rbs", text)) is not None
    assert nest(sys.getrecursionlimit() - _stack_depth() - 150) is None
