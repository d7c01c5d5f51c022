"""Why a rule is unknown although its data came (rubass/engine/unknowns.py): each computed unknown the
acceptance tester found without a reason in /diagnostics now has one, naming the cause and the values;
and the verdict of each case is the contract's (LANGUAGE.md §5, §12): x / 0, sqrt of a negative, an
element past the end, min/max of an empty array or slice are unknown; a quotient too large for a float is
inf, a number, so `1e200 / 1e-200 > 2` is true."""
import math
import os

from rubass.actions import status
from rubass.engine import UNKNOWN, Engine
from rubass.engine.unknowns import reasons, rule_reasons
from rubass.lang import check_text

from conftest import ROOT

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")


def engine(rules):
    spec = check_text("action primitive warn;\nentity a { rules:\n" + rules + "\n}\nif (a.r) then { warn; }\n",
                      os.path.join(ROOT, "x.rbs"), [LIB])
    e = Engine(spec, 0.0)
    e.evaluate_all(0.0)
    return e


def why(e):
    return rule_reasons(e.spec, e.store).get("a.r", [])


def test_division_by_zero_is_unknown_and_says_so_with_the_values():
    e = engine("r: topic /a.data / topic /b.data > 2;")
    e.on_message("/a", 1.0, {"data": 1e200})
    e.on_message("/b", 1.0, {"data": 0.0})
    assert e.store.rules["a.r"] is UNKNOWN
    assert why(e) == ["division by zero: topic /a.data / topic /b.data is 1e+200 / 0"]


def test_a_quotient_too_large_is_infinity_a_number_not_unknown():
    e = engine("r: topic /a.data / topic /b.data > 2;")
    e.on_message("/a", 1.0, {"data": 1e200})
    e.on_message("/b", 1.0, {"data": 1e-200})
    assert e.store.rules["a.r"] is True
    assert why(e) == []


def test_not_a_number_from_arithmetic_names_the_operation():
    e = engine("r: topic /a.data - topic /b.data > 2;")
    e.on_message("/a", 1.0, {"data": math.inf})
    e.on_message("/b", 1.0, {"data": math.inf})
    assert e.store.rules["a.r"] is UNKNOWN
    assert why(e) == ["not a number: topic /a.data - topic /b.data is inf - inf"]


def test_an_index_past_the_end_says_the_index_and_what_the_array_may_be():
    e = engine("r: topic /arr.data[5] > 1;")
    e.on_message("/arr", 1.0, {"data": [1.0, 2.0]})
    assert e.store.rules["a.r"] is UNKNOWN
    (reason,) = why(e)
    assert "topic /arr.data[5]" in reason and "index out of range" in reason and "fewer than 6 elements" in reason


def test_an_index_past_the_end_gives_the_length_when_the_spec_reads_the_array():
    e = engine("r: topic /arr.data[5] > 1 or len(topic /arr.data) > 9;")
    e.on_message("/arr", 1.0, {"data": [1.0, 2.0]})
    assert e.store.rules["a.r"] is UNKNOWN
    assert why(e) == ["index out of range: topic /arr.data[5] in an array of 2 elements (/arr.data in the last message)"]


def test_min_of_an_empty_array_and_max_of_an_empty_slice():
    e = engine("r: min(topic /arr.data) > 1;")
    e.on_message("/arr", 1.0, {"data": []})
    assert e.store.rules["a.r"] is UNKNOWN
    (reason,) = why(e)
    assert reason.startswith("min(topic /arr.data) of an empty array"), reason
    e = engine("r: max(topic /arr.data[1:3]) > 1;")
    e.on_message("/arr", 1.0, {"data": []})
    assert e.store.rules["a.r"] is UNKNOWN
    (reason,) = why(e)
    assert reason.startswith("max(topic /arr.data[1:3]) of an empty slice"), reason


def test_min_of_only_nan_says_no_number():
    e = engine("r: min(topic /arr.data) > 1;")
    e.on_message("/arr", 1.0, {"data": [math.nan, math.nan]})
    assert e.store.rules["a.r"] is UNKNOWN
    assert why(e) == ["min(topic /arr.data): no number among the 2 elements of /arr.data (all NaN)"]


def test_sqrt_of_a_negative_number():
    e = engine("r: sqrt(topic /b.data) > 1;")
    e.on_message("/b", 1.0, {"data": -4.0})
    assert e.store.rules["a.r"] is UNKNOWN
    assert why(e) == ["sqrt of a negative number: sqrt(topic /b.data) is sqrt(-4)"]


def test_a_nan_field_and_a_cause_inside_for():
    e = engine("r: (topic /b.data / topic /c.data > 1) for 1 s;")
    e.on_message("/b", 1.0, {"data": math.nan})
    e.on_message("/c", 1.0, {"data": 0.0})
    assert e.store.rules["a.r"] is not True
    assert why(e) == ["topic /b.data is NaN (or unreadable) in the last message"]
    e.on_message("/b", 1.5, {"data": 3.0})
    assert why(e) == ["division by zero: topic /b.data / topic /c.data is 3 / 0"]


def test_no_message_yet_is_left_to_the_data_level_reasons_and_known_rules_get_none():
    e = engine("r: topic /a.data / topic /b.data > 2;")
    assert e.store.rules["a.r"] is UNKNOWN
    assert why(e) == []  # status.unknown_reasons says "no message on /a yet"
    e.on_message("/a", 1.0, {"data": 6.0})
    e.on_message("/b", 1.0, {"data": 2.0})
    assert e.store.rules["a.r"] is True and rule_reasons(e.spec, e.store) == {}


def test_a_frequency_window_not_yet_full():
    e = engine("r: frequency(topic /a, 2 s) < 5 Hz;")
    assert why(e) == ["frequency(topic /a, 2 s): /a watched for less than its 2 s window yet"]


def test_reasons_is_pure_and_leaves_the_store_alone():
    e = engine("r: topic /a.data / topic /b.data > 2;")
    e.on_message("/a", 1.0, {"data": 1.0})
    e.on_message("/b", 1.0, {"data": 0.0})
    before = dict(e.store.fields), dict(e.store.rules)
    reasons(e.spec.rule("a.r").expr, e.store)
    assert (dict(e.store.fields), dict(e.store.rules)) == before


def test_the_status_lists_the_computed_reason_beside_the_rule():
    e = engine("r: topic /a.data / topic /b.data > 2;")
    e.on_message("/a", 1.0, {"data": 1e200})
    e.on_message("/b", 1.0, {"data": 0.0})
    topics = {t: {"messages": 1, "errors": []} for t in ("/a", "/b")}
    entity, _ = status.build(e.spec, dict(e.store.rules), [], topics, {}, {}, {"master": "connected"},
                             computed=rule_reasons(e.spec, e.store))
    values = dict(entity.values)
    assert values["r"] == "unknown"
    assert values["r unknown because"] == "division by zero: topic /a.data / topic /b.data is 1e+200 / 0"
    assert entity.level == status.OK  # unknown, not a data error


def test_a_count_made_unknown_by_one_nan_element_names_that_element():
    e = engine("r: count(topic /scan.ranges[*] < 0.4 m) > 2;")
    e.on_message("/scan", 1.0, {"ranges": [1.0, math.nan, 0.1]})
    assert e.store.rules["a.r"] is UNKNOWN
    assert why(e) == ["count(/scan.ranges[*] < 0.4 m): its condition is unknown for element 1 of "
                      "/scan.ranges[*] (it is NaN or missing there)"]


def test_an_any_decided_by_another_element_is_known_and_gives_no_reason():
    e = engine("r: any(topic /scan.ranges[*] < 0.4 m);")
    e.on_message("/scan", 1.0, {"ranges": [math.nan, 0.1]})
    assert e.store.rules["a.r"] is True
    assert rule_reasons(e.spec, e.store) == {}
    e.on_message("/scan", 2.0, {"ranges": [math.nan, 1.0]})
    assert e.store.rules["a.r"] is UNKNOWN
    (reason,) = why(e)
    assert "element 0 of /scan.ranges[*]" in reason, reason


def test_a_field_the_message_lacks_is_left_to_the_data_error_not_called_nan():
    e = engine("r: topic /a.data > 2;")
    e.on_message("/a", 1.0, {"other": 1.0})
    assert e.field_errors and e.store.rules["a.r"] is UNKNOWN
    assert rule_reasons(e.spec, e.store, e.field_errors) == {}


def test_a_snapshot_gives_the_same_reasons_and_does_not_follow_later_messages():
    from rubass.engine.unknowns import snapshot
    e = engine("r: topic /a.data / topic /b.data > 2 or frequency(topic /a) > 9;")
    e.on_message("/a", 1.0, {"data": 1.0})
    e.on_message("/b", 1.0, {"data": 0.0})
    snap = snapshot(e.store)
    assert rule_reasons(e.spec, snap) == rule_reasons(e.spec, e.store)
    e.on_message("/b", 1.5, {"data": 0.25})  # the engine goes on; the snapshot stays as it was
    assert "division by zero" in rule_reasons(e.spec, snap)["a.r"][0]
    assert not any("division" in r for r in rule_reasons(e.spec, e.store).get("a.r", []))


def test_a_reason_inside_a_quantifier_quotes_the_term_as_written_not_a_class_name():
    """Review finding: the printer does not know an element `[*]`, so the reason read "Binary is 1 / 0"."""
    e = engine("r: any(topic /a.data[*] / 0 > 1);")
    e.on_message("/a", 1.0, {"data": [1.0]})
    assert e.store.rules["a.r"] is UNKNOWN
    got = " ".join(why(e))
    assert "Binary" not in got and "division by zero: topic /a.data[*] / 0 is 1 / 0" in got, got


def test_min_over_every_element_of_an_empty_array_says_array_not_slice():
    """Re-sweep finding: `[*]` is the whole array, but the reason said 'of an empty slice'."""
    e = engine("r: min(topic /diag.status[*].level) > 1;")
    e.on_message("/diag", 1.0, {"status": []})
    assert e.store.rules["a.r"] is UNKNOWN
    assert why(e)[0].startswith("min(topic /diag.status[*].level) of an empty array"), why(e)
