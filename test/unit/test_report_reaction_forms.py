"""The report's reaction by design for every time-dependent form, not only `age(topic X) > T`.

Acceptance finding: `not (age(…) <= 1 s)`, `age(…) - 0.5 s > 0.5 s`, `max(age, age) > 1 s`, `2 * age > 3 s`,
`stamp_age > 1.5 s` and `frequency(…, 2 s) < 20 Hz` all showed "immediate". A figure is an upper bound or
it is "not computed: …", never smaller than the truth.
"""
import pytest

from rubass.lang import ast, check_text
from rubass.report.design import design

RULES = {
    "negated": ("not (age(topic /fix) <= 1 s)", 1.0),
    "shifted": ("age(topic /fix) - 0.5 s > 0.5 s", 1.0),
    "either_silent": ("max(age(topic /fix), age(topic /imu)) > 1 s", 1.0),
    "both_silent": ("min(age(topic /fix), age(topic /imu)) > 1 s", 1.0),
    "scaled": ("2 * age(topic /fix) > 3 s", 1.5),
    "halved": ("age(topic /fix) / 2 > 1 s", 2.0),
    "reversed": ("1 s < age(topic /fix)", 1.0),
    "negative": ("-age(topic /fix) < -1 s", 1.0),
    "stamp": ("stamp_age(topic /fix) > 1.5 s", 1.5),
    "window": ("frequency(topic /imu, 2 s) < 20 Hz", 2.0),
    "default_window": ("frequency(topic /imu) < 20 Hz", 1.0),
    "flood": ("frequency(topic /imu, 0.5 s) > 200 Hz", 0.5),
    # one topic silent while the other keeps publishing (its age near 0): the slower case, 2 s, not 1 s
    "sum": ("age(topic /fix) + age(topic /imu) > 2 s", 2.0),
    "mixed": ("max(age(topic /fix), 2 * age(topic /imu)) - 1 s > 2 s", 3.0),
    "fresh": ("age(topic /fix) < 1 s", 0.0),  # true when a message comes
    "held": ("(age(topic /fix) > 1 s) for 2 s", 3.0),
    "not_held": ("not ((age(topic /fix) > 1 s) for 2 s)", 0.0),  # false as soon as a message comes
    "stale_window": ("(topic /fix.latitude > 1) within 2 s", 0.0),
}
UNKNOWN = {
    "difference": "age(topic /a) - age(topic /b) > 1 s",
    "product": "age(topic /a) * age(topic /b) > 1",
    "field_limit": "age(topic /a) > topic /lim.data",
    "kink": "abs(age(topic /a) - 3 s) > 1 s",
    "in_quantifier": "any(topic /d.status[*].level > age(topic /a))",
}


@pytest.fixture(scope="module")
def spec():
    lines = [f"  {name}: {text};" for name, (text, _) in RULES.items()]
    lines += [f"  {name}: {text};" for name, text in UNKNOWN.items()]
    return check_text("entity g { rules:\n" + "\n".join(lines) + "\n  either: g.scaled or g.difference;\n}\n")


@pytest.mark.parametrize("name", sorted(RULES))
def test_each_time_form_has_its_upper_bound(spec, name):
    d = design(spec, ast.RuleRef(f"g.{name}"))
    assert not d.unknown
    assert d.total == pytest.approx(RULES[name][1])
    assert (d.text() == "immediate") == (RULES[name][1] == 0.0)


@pytest.mark.parametrize("name", sorted(UNKNOWN))
def test_what_cannot_be_bounded_says_so(spec, name):
    d = design(spec, ast.RuleRef(f"g.{name}"))
    assert d.unknown and d.text().startswith("not computed: ")
    assert "immediate" not in d.text()


def test_a_slowest_path_through_an_unbounded_operand_is_not_a_figure(spec):
    d = design(spec, ast.RuleRef("g.either"))
    assert d.text().startswith("not computed: ") and "age of /b counts against it" in d.text()


def test_the_difference_names_the_age_that_counts_against_it(spec):
    assert "the age of /b counts against it" in design(spec, ast.RuleRef("g.difference")).text()


def test_node_statistics_take_their_samples():
    spec = check_text("entity n: base { rules:\n  dead: not alive(node base);\n  busy: (cpu(node base) > 80 %) for 1.5 s;\n}\n")
    assert design(spec, ast.RuleRef("n.dead")).chain == [0.2]
    assert design(spec, ast.RuleRef("n.busy")).chain == [0.2, 1.5]
