"""The report's reaction by design: the time on a rule's or behaviour's slowest path from its inputs.

Acceptance finding: every `for`/`within` of an expression was summed, so an `or` of two `for`s read
as their sum, a `within` as a delay, and `active()` (an escalation ladder) and `age() > T` as nothing.
"""
import pytest

from rubass.lang import ast, check_text
from rubass.report.design import design_chain

from conftest import ROOT

LIB = f"{ROOT}/docs/examples/actions.yaml"
LADDER = """action primitive warn, slow_down, stop, board_stop;
entity base {
  rules:
    too_fast: abs(topic /odom.twist.twist.linear.x) > 0.5 m/s;
    moving: abs(topic /odom.twist.twist.linear.x) > 0.05 m/s;
    slow_too_fast: (topic /odom.twist.twist.linear.x > 0.5 m/s) for 0.4 s;
    either: (base.slow_too_fast for 1 s) or (base.moving for 1 s);
    same: (base.moving for 1 s) or (base.moving for 2 s);
    held: (topic /odom.twist.twist.linear.x > 1 m/s) within 2 s;
    silent: age(topic /cmd) > 0.5 s;
    silent_long: (age(topic /cmd) > 0.5 s) for 1 s;
    latched: latch(base.slow_too_fast, not base.moving);
}
caution: if (base.too_fast) then { warn("over 0.5 m/s"); }
slow: if ((active(warn) for 1 s) and base.too_fast) then { slow_down; }
halt: if ((active(slow_down) for 2 s) and base.too_fast) then { stop; }
cut_power: if ((active(stop) for 0.5 s) and base.moving) then { board_stop; }
"""


@pytest.fixture(scope="module")
def spec():
    return check_text(LADDER, extra_libraries=[LIB])


@pytest.mark.parametrize("rule,chain", [
    ("base.too_fast", []),
    ("base.slow_too_fast", [0.4]),
    ("base.either", [0.4, 1.0]),  # the slower branch, not 0.4 + 1 + 1
    ("base.same", [2.0]),  # not 3 s
    ("base.held", []),  # true at once: `within` holds it after, it does not delay it
    ("base.silent", [0.5]),  # seen 0.5 s after the last message
    ("base.silent_long", [0.5, 1.0]),
    ("base.latched", [0.4]),
])
def test_a_rules_chain(spec, rule, chain):
    assert design_chain(spec, ast.RuleRef(rule)) == chain


@pytest.mark.parametrize("name,total", [("caution", 0.0), ("slow", 1.0), ("halt", 3.0), ("cut_power", 3.5)])
def test_an_escalation_ladder_adds_each_rung(spec, name, total):
    """As its rule test shows: warn at once, slow_down after 1 s, stop after 3 s, board_stop after 3.5 s."""
    b = next(b for b in spec.behaviours if b.name == name)
    assert sum(design_chain(spec, b.cond, frozenset({b.index}))) == pytest.approx(total)
