"""The engine with a manual clock: exact `for`, unknowns, latching and reset, locality."""
import os

from rubass.engine import UNKNOWN, Engine
from rubass.lang import check_text

from conftest import ROOT

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")


def engine(body, now=0.0):
    spec = check_text("action primitive stop, warn;\n" + body, os.path.join(ROOT, "x.rbs"), [LIB])
    e = Engine(spec, now)
    e.evaluate_all(now)
    return e


def starts(events):
    return [(round(ev.time, 9), ev.behaviour) for ev in events if ev.kind == "start"]


def test_fig2_fires_at_exactly_t0_plus_both_durations():
    text = open(os.path.join(ROOT, "config", "fig2.rbs")).read()
    e = Engine(check_text(text, os.path.join(ROOT, "config", "fig2.rbs"), [LIB]), 0.0)
    e.evaluate_all(0.0)
    e.on_message("/cmd_vel_left", 1.0, {"linear": {"x": 0.5}})
    e.on_message("/encoder_left", 1.0, {"data": 0})
    assert e.next_deadline() == 1.4
    assert e.advance(1.4)[-1].value is True
    assert e.next_deadline() == 2.4
    assert starts(e.advance(10.0)) == [(2.4, 1)]


def test_any_false_evaluation_restarts_for():
    e = engine("entity a { rules: r: (topic /x.data > 1) for 1 s; }\nif (a.r) then { warn; }\n")
    e.on_message("/x", 0.0, {"data": 2})
    e.on_message("/x", 0.5, {"data": 0})
    e.on_message("/x", 0.6, {"data": 2})
    assert e.next_deadline() == 1.6
    assert starts(e.advance(1.59)) == []
    assert starts(e.advance(1.6)) == [(1.6, 1)]


def test_unknown_never_fires_and_nan_is_unknown():
    e = engine("entity a { rules: r: topic /x.data > 1 or topic /y.data > 1; }\nif (a.r) then { warn; }\n")
    assert e.rule_value("a.r") is UNKNOWN
    e.on_message("/x", 0.1, {"data": float("nan")})
    assert e.rule_value("a.r") is UNKNOWN
    e.on_message("/y", 0.2, {"data": 3})
    assert e.rule_value("a.r") is True  # true or unknown = true


def test_latched_behaviour_holds_until_reset_after_cause_is_gone():
    e = engine("entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { stop; }\n")
    assert starts(e.on_message("/x", 1.0, {"data": 5})) == [(1.0, 1)]
    assert e.reset(1.5) == []  # cause still there: reset does nothing
    assert [ev.kind for ev in e.on_message("/x", 2.0, {"data": 0}) if ev.kind != "rule"] == []
    assert [ev.kind for ev in e.on_tick(2.1) if ev.kind != "rule"] == ["hold"]
    assert [(ev.kind, ev.behaviour) for ev in e.reset(3.0)] == [("release", 1)]


def test_non_latched_behaviour_releases():
    e = engine("entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { warn; }\n")
    e.on_message("/x", 1.0, {"data": 5})
    assert [ev.kind for ev in e.on_message("/x", 2.0, {"data": 0}) if ev.kind != "rule"] == ["release"]


def test_age_counts_from_watch_start_and_fires_at_its_crossing_not_the_next_tick():
    e = engine("entity a { rules: silent: age(topic /odom) > 0.5 s; }\nif (a.silent) then { warn; }\n", now=10.0)
    assert starts(e.on_tick(10.4)) == []
    assert e.next_deadline() == 10.5 + 1e-6
    assert starts(e.on_tick(10.6)) == [(10.500001, 1)]


def test_missing_field_is_an_error_and_unknown():
    e = engine("entity a { rules: r: topic /x.dtaa > 1; }\nif (a.r) then { warn; }\n")
    e.on_message("/x", 1.0, {"data": 5})
    assert e.rule_value("a.r") is UNKNOWN
    assert e.field_errors == {("/x", "('dtaa',)"): "no field 'dtaa'"}


def test_a_message_reevaluates_only_its_dependents():
    body = "".join(f"entity e{i} {{ rules: r: topic /t{i}.data > 1; }}\n" for i in range(50))
    e = engine(body + "if (e0.r) then { warn; }\n")
    events = e.on_message("/t7", 1.0, {"data": 5})
    assert [ev.rule for ev in events] == ["e7.r"]


def build(body, now):
    spec = check_text("action primitive stop, warn;\n" + body, os.path.join(ROOT, "x.rbs"), [LIB])
    return Engine(spec, now)


def test_reload_keeps_unchanged_rules_timers_and_active_behaviours():
    a = "entity a { rules: r: (topic /x.data > 1) for 1 s; q: topic /y.data > 1; }\n"
    old = build(a + "if (a.r) then { warn; }\nif (a.q) then { stop; }\n", 0.0)
    old.evaluate_all(0.0)
    old.on_message("/x", 0.5, {"data": 2})
    old.on_message("/y", 0.6, {"data": 2})  # behaviour 2 active
    new = build(a.replace("q: topic /y.data > 1", "q: topic /y.data > 5") + "if (a.q) then { stop; }\n"
                "if (a.r) then { warn; }\n", 0.0)
    events = new.adopt(old, 0.8)
    assert new.next_deadline() == 1.5  # the unchanged `for` keeps counting from 0.5
    assert [(e.kind, e.behaviour) for e in events if e.kind != "rule"] == []  # `if (a.r)` did not restart
    assert new.rule_value("a.q") is False  # changed rule re-evaluated on the kept data
    assert [(e.kind, e.behaviour) for e in new.advance(2.0) if e.kind != "rule"] == [("start", 2)]
    # `if (a.q) then { stop; }` is the same behaviour (condition and actions as written), moved to
    # number 1: carried, and its latched stop stays on though its edited rule is false now
    assert new.active_behaviours() == [1, 2] and new.orphans == []


def test_an_edited_for_rule_keeps_its_history_so_an_active_stop_is_not_released():
    """Acceptance finding: `fast: (topic /speed.data > 1) for 1 s` active, edited to `> 1.1` and
    reloaded with the speed still 2.0: released at the reload and started again 1 s later (no stop
    for 1.089 s). An edited rule's `for`/`within`/`latch` now keep their state when they line up."""
    a = "entity a {{ rules: fast: (topic /speed.data > {}) for 1 s; }}\nfastb: if (a.fast) then {{ warn; }}\n"
    old = build(a.format(1), 0.0)
    old.evaluate_all(0.0)
    old.on_message("/speed", 0.5, {"data": 2.0})
    assert [e.kind for e in old.advance(1.5) if e.kind != "rule"] == ["start"]
    new = build(a.format(1.1), 0.0)
    assert [e.kind for e in new.adopt(old, 2.0) if e.kind != "rule"] == []  # still violated: nothing
    assert new.active_behaviours() == [1]
    assert [e.kind for e in new.on_message("/speed", 2.5, {"data": 2.0}) if e.kind != "rule"] == []
    assert [e.kind for e in new.on_message("/speed", 3.0, {"data": 1.05}) if e.kind != "rule"] == ["release"]
    # relaxed past the current value: the edit does not hold, the stop is released at the reload
    again = build(a.format(3), 0.0)
    new.on_message("/speed", 3.5, {"data": 2.0})
    new.advance(4.6)
    assert new.active_behaviours() == [1]
    assert [e.kind for e in again.adopt(new, 5.0) if e.kind != "rule"] == ["release"]


def test_reload_watches_new_topics_from_the_swap():
    old = build("entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { warn; }\n", 0.0)
    new = build("entity a { rules: r: age(topic /z) > 1 s; }\nif (a.r) then { warn; }\n", 0.0)
    new.adopt(old, 10.0)
    assert new.next_deadline() == 11.0 + 1e-6


def test_behaviour_rules_names_the_true_causes():
    e = engine("entity a { rules: p: topic /x.data > 1; q: topic /y.data > 1; }\nif (a.p or a.q) then { warn; }\n")
    e.on_message("/y", 1.0, {"data": 3})
    assert e.behaviour_rules(1) == ["a.q"]


def test_an_unnamed_behaviour_is_the_same_behaviour_when_a_rule_it_names_is_edited():
    """Re-sweep finding: the carry above worked for a named behaviour only; an unnamed one (as the
    README writes them) took the rules' texts into its identity, so the edit made it another
    behaviour: released at the reload (on_release sent) and started again."""
    from rubass.actions.dispatch import Dispatcher

    a = "entity a {{ rules: fast: (topic /speed.data > {}) for 1 s; }}\nif (a.fast) then {{ warn; }}\n"
    old = build(a.format(1), 0.0)
    old.evaluate_all(0.0)
    old.on_message("/speed", 0.5, {"data": 2.0})
    assert [e.kind for e in old.advance(1.5) if e.kind != "rule"] == ["start"]
    new = build(a.format(1.1), 0.0)
    assert Dispatcher.keys(old.spec.behaviours) == Dispatcher.keys(new.spec.behaviours)
    assert [e.kind for e in new.adopt(old, 2.0) if e.kind != "rule"] == []
    assert new.active_behaviours() == [1] and not new.orphans
    assert [e.kind for e in new.on_message("/speed", 3.0, {"data": 1.05}) if e.kind != "rule"] == ["release"]
