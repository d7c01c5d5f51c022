"""Evaluation shortcuts (issue 17) give the values of the general path: `and`/`or` chains
without operators are short-circuited (still the Kleene fold of every term, whatever the order
of true, false and unknown terms), and a comparison with a number is one closure."""
import math
import os
from functools import reduce

from hypothesis import given, settings
from hypothesis import strategies as st

from rubass.engine.evaluate import Compiler
from rubass.engine.store import Store
from rubass.engine.values import UNKNOWN, k_and, k_or
from rubass.lang import check_text

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")
N = 6
RULES = "\n".join(f"  r{i}: topic /t{i}.data > 0;" for i in range(N))
SPEC = ("action primitive warn;\nentity e { rules:\n" + RULES + "\n}\n"
        + "if (" + " or ".join(f"e.r{i}" for i in range(N)) + ") then { warn; }\n"
        + "if (" + " and ".join(f"e.r{i}" for i in range(N)) + ") then { warn; }\n"
        # stateless terms that are not rule names: fields read directly
        + "if (" + " or ".join(f"topic /t{i}.data > 0" for i in range(N)) + ") then { warn; }\n"
        + "if (" + " and ".join(f"topic /t{i}.data > 0" for i in range(N)) + ") then { warn; }\n")
KLEENE = st.sampled_from([True, False, UNKNOWN, None])  # None: a rule not evaluated yet
FIELD = st.sampled_from([1.0, -1.0, math.nan, UNKNOWN])


def _compiled():
    spec = check_text(SPEC, os.path.join(ROOT, "x.rbs"), [LIB])
    store = Store(0.0)
    compiler = Compiler(store, {"warn": [False]})
    return store, [compiler.compile(b.cond).fn for b in spec.behaviours]


STORE, FNS = _compiled()


@settings(max_examples=400, deadline=None)
@given(st.lists(KLEENE, min_size=N, max_size=N))
def test_a_chain_of_rule_names_is_the_kleene_fold_of_its_rules(values):
    STORE.rules.clear()
    STORE.rules.update({f"e.r{i}": v for i, v in enumerate(values) if v is not None})
    known = [UNKNOWN if v is None else v for v in values]
    assert FNS[0]() is reduce(k_or, known)
    assert FNS[1]() is reduce(k_and, known)


@settings(max_examples=400, deadline=None)
@given(st.lists(FIELD, min_size=N, max_size=N))
def test_a_chain_of_comparisons_is_the_kleene_fold_of_its_terms(values):
    for i, v in enumerate(values):
        STORE.cell((f"/t{i}", ("data",)))[0] = v
    terms = [UNKNOWN if v is UNKNOWN or v != v else v > 0 for v in values]
    assert FNS[2]() is reduce(k_or, terms)
    assert FNS[3]() is reduce(k_and, terms)


def test_a_term_with_an_operator_is_still_evaluated_every_time():
    # `for` inside a chain must see every evaluation, even when an earlier term decides it
    spec = check_text("action primitive warn;\nentity e { rules: a: topic /a.data > 0; b: topic /b.data > 0; }\n"
                      "if (e.a or (e.b for 1 s)) then { warn; }\n", os.path.join(ROOT, "x.rbs"), [LIB])
    store = Store(0.0)
    compiled = Compiler(store, {"warn": [False]}).compile(spec.behaviours[0].cond)
    store.cell(("/b", ("data",)))[0] = 1.0
    store.rules.update({"e.a": True, "e.b": True})
    compiled.fn()  # e.a decides, and e.b's `for` starts counting now, at 0
    store.rules["e.a"] = False
    store.now = 1.0
    assert compiled.fn() is True  # e.b has held for 1 s: the `for` saw the first evaluation


ANY_VALUE = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.sampled_from([UNKNOWN, True, False, 0, 1, "x"]))


@settings(max_examples=300, deadline=None)
@given(st.sampled_from(["<", "<=", ">", ">="]), st.floats(allow_nan=False, allow_infinity=True), ANY_VALUE,
       st.booleans())
def test_a_comparison_with_a_number_is_the_operator_tables_comparison(op, const, value, const_left):
    from rubass.engine.evaluate import _compare_with_constant
    from rubass.lang import ast
    from rubass.lang.ops import BINARY

    x = ast.TopicRef("/t", ("data",))
    c = ast.Lit(const)
    e = ast.Binary(op, c, x) if const_left else ast.Binary(op, x, c)
    fast = _compare_with_constant(e, lambda: const if const_left else value, lambda: value if const_left else const)
    assert fast is not None
    expected = BINARY[op](const, value) if const_left else BINARY[op](value, const)
    assert fast() is expected


@settings(max_examples=200, deadline=None)
@given(ANY_VALUE)
def test_abs_is_the_operator_tables_abs(value):
    from rubass.lang import ast
    from rubass.lang.ops import scalar_fn

    store = Store(0.0)
    store.cell(("/t", ("data",)))[0] = value
    fn = Compiler(store, {})._fn(ast.Call("abs", (ast.TopicRef("/t", ("data",)),)), [], None)
    got, expected = fn(), scalar_fn("abs")(value)
    assert got is expected or got == expected and type(got) is type(expected)


def test_a_condition_is_true_false_or_unknown_without_as_bool_at_its_root():
    spec = check_text("action primitive warn;\nentity e { rules: a: topic /a.data > 0; b: not (topic /b.data > 0);\n"
                      "  c: (topic /a.data > 0) for 1 s; d: topic /f.data; }\nif (e.a) then { warn; }\n",
                      os.path.join(ROOT, "x.rbs"), [LIB])
    store = Store(0.0)
    compiler = Compiler(store, {"warn": [False]})
    fns = {r.key: compiler.compile(r.expr).fn for r in spec.rules}
    for a, f in [(1.0, 1.0), (-1.0, math.nan), (UNKNOWN, 2.0), (math.inf, 0.0)]:
        store.cell(("/a", ("data",)))[0] = a
        store.cell(("/b", ("data",)))[0] = a
        store.cell(("/f", ("data",)))[0] = f  # a number where a boolean field was expected: unknown
        for key, fn in fns.items():
            value = fn()
            assert value is True or value is False or value is UNKNOWN, (key, a, value)
        assert fns["e.d"]() is UNKNOWN
