"""Mistakes the parser used to stop at alone ("1 error"), now reported by the checker beside
every other error of the spec (README: past a syntax error, all errors in one run): a second
slice in a field path, an index that is no index ('[0.5]'), a number too large (1e999)."""
import pytest
from hypothesis import given, settings, strategies as st

from rubass.lang import SpecError, format_spec
from rubass.lang.grammar import parse_source
from rubass.lang.loader import check_source
from rubass.lang.modelfile import parse_model
from rubass.lang.source import Source

LIB = "actions:\n  warn: {plugin: log}\n"
HEAD = 'import "actions.yaml";\naction primitive warn;\n'
MODEL = """\
rubass_model: 1
topics:
  /odom: t_msgs/Odom
  /diag: t_msgs/Diags
  /scan: t_msgs/Scan
definitions:
  t_msgs/Odom: |
    float64 x
    float64 t
  t_msgs/KV: |
    string key
  t_msgs/Status: |
    byte level
    t_msgs/KV[] values
  t_msgs/Diags: |
    t_msgs/Status[] status
  t_msgs/Scan: |
    float32[] ranges
units:
  t_msgs/Odom: {x: m/s}
"""
ONE_ARRAY = "a field path can run over one array only: one '[*]' or '[A:B]'"


def not_an_index(bad):
    return (f"'{bad}' is not an index: write an integer ([0], [-1]), a slice of integers ([0:90], [-90:]) "
            "or [*] for the whole array")


def errors(tmp_path, body, model=None):
    (tmp_path / "actions.yaml").write_text(LIB)
    path = tmp_path / "s.rbs"
    path.write_text(HEAD + body)
    with pytest.raises(SpecError) as info:
        check_source(Source(str(path), HEAD + body), model=model)
    return [(d.span.line, d.span.col, d.message) for d in info.value.diagnostics]


@pytest.fixture
def model():
    m, diags = parse_model(Source("robot.yaml", MODEL))
    assert m is not None, diags
    return m


BODY = ("entity e {\n  rules:\n    a: topic /odom.x > 3 s;\n    {}\n    c: topic /odom.positon > 1;\n}\n"
        "if (e.a or e.c) then {{ warn; }}\n")


@pytest.mark.parametrize("rule, col, message", [
    ('b: count(topic /diag.status[*].values[*].key == "x") > 1;', 14, ONE_ARRAY),
    ("b: min(topic /diag.status[*].values[0:2].key) > 1;", 12, ONE_ARRAY),
    ("b: topic /scan.ranges[0.5] > 1;", 26, not_an_index("[0.5]")),
    ("b: max(topic /scan.ranges[ 1.5 ]) > 1;", 30, not_an_index("[ 1.5 ]")),
    ("b: any(topic /scan.ranges[a:b] > 1);", 30, not_an_index("[a:b]")),
    ("b: topic /odom.t > 1e999;", 24, "the number '1e999' is too large (the largest is about 1.8e308)"),
    ("b: topic /odom.t > -1e999;", 24, "the number '1e999' is too large (the largest is about 1.8e308)"),
    ("b: topic /odom.t > 2e400 s;", 24, "the number '2e400' is too large (the largest is about 1.8e308)"),
])
def test_the_mistake_is_reported_with_every_other_error_of_the_spec(tmp_path, model, rule, col, message):
    body = BODY.replace("{}", rule, 1).replace("{{", "{").replace("}}", "}")
    got = errors(tmp_path, body, model)
    assert got == [(5, 22, "compares a speed with a time"), (6, col, message),
                   (7, 8, "t_msgs/Odom has no field 'positon' (its fields: x, t)")]  # one error for the mistake


@pytest.mark.parametrize("rule", [
    "a: any(topic /d.s[*].v[*].k == 1);",
    "a: topic /s.r[0.5] > 1;",
    "a: topic /s.r[] > 1;",
    "a: topic /s.r > 1e999;",
])
def test_without_a_model_too(tmp_path, rule):
    body = f"entity e {{ rules:\n  {rule}\n  b: nope > 1;\n}}\nif (e.a or e.b) then {{ warn; }}\n"
    got = errors(tmp_path, body)
    assert [line for line, _, _ in got] == [4, 5], got
    assert got[1][2] == "undefined name 'nope'"


@pytest.mark.parametrize("text", [
    "const x = 1e999;\nentity e { rules: r: topic /a.b[*].c[0:2] > 1 and topic /a.b[0.5] > 2e999 m; }\n",
    "entity e { rules: r: topic /a.b[ x ] > -1e999; }\n",
])
def test_both_parsers_read_the_same_tree_and_fmt_keeps_what_was_written(text):
    fast = parse_source(Source("t.rbs", text))
    assert fast == parse_source(Source("t.rbs", text), fast=False)
    out = format_spec(fast, text)
    assert parse_source(Source("t.rbs", out)) == fast
    for kept in ("1e999", "[0.5]", "[*].c[0:2]", "[ x ]"):
        if kept in text:
            assert kept in out, out


def test_syntax_errors_after_a_topic_are_still_syntax_errors():
    with pytest.raises(SpecError) as info:
        parse_source(Source("t.rbs", "entity e { rules: r: topic /a.b[0 > 1; }\n"))
    assert "is not an index" in str(info.value)


_INNER = st.text(alphabet="0123456789.-:*ab x", min_size=0, max_size=8)


@settings(max_examples=150, deadline=None)
@given(_INNER)
def test_any_bracket_after_a_path_is_an_index_a_slice_or_one_error_at_its_bracket(inner):
    """Property: `[…]` after a field path parses; it checks clean as a valid index or slice, or
    gives exactly one error, at the '[', beside the spec's other error (an undefined name)."""
    head = "entity e { rules:\n  a: max(topic /s.r"
    text = f"{head}[{inner}]) > 1;\n  b: nope > 1;\n}}\n"
    try:
        check_source(Source("p.rbs", text))
    except SpecError as exc:
        got = [(d.span.line, d.span.col, d.message) for d in exc.diagnostics]
    else:
        raise AssertionError("the undefined name was not reported")
    assert got[-1] == (3, 6, "undefined name 'nope'"), got
    first = got[:-1]
    assert len(first) <= 1, got
    if first:
        line, col, message = first[0]
        assert line == 2 and message.startswith(("'[", "a slice", "an array term", "the")), got
        if message.startswith("'["):
            assert (col, message) == (len(head.split("\n")[-1]) + 1, not_an_index(f"[{inner}]")), got


@pytest.mark.parametrize("rule, col", [
    ("a: (topic /s.r > 1) for 1e999 s;", 27),
    ("a: inside(topic /p.x, topic /p.y, polygon((1e999 m, 0 m), (1 m, 0 m), (0 m, 1 m)));", 46),
    ("a: inside(topic /p.x, topic /p.y, polygon((1 parsec, 0 m), (1 m, 0 m), (0 m, 1 m)));", 46),
])
def test_a_number_too_large_or_a_bad_unit_is_one_error_wherever_it_is(tmp_path, rule, col):
    got = errors(tmp_path, f"entity e {{ rules:\n  {rule}\n}}\nif (e.a) then {{ warn; }}\n")
    assert len(got) == 1 and got[0][:2] == (4, col), got
