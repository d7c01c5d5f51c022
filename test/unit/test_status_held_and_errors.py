"""/diagnostics says what holds the robot and what cannot be read, whatever the rule's value:
an entity whose rule reads a field it cannot read is ERROR even when the rule is false (`false
and unknown` is false), and a stop held for rules a reload removed makes the monitor WARN."""
from rubass.actions import status
from rubass.lang import check_text

SPEC = "entity laser { rules: protective: topic /scan.a < 0.5 and topic /scan.b < 9; }\n"
ERR = "rule 'laser.protective' reads /scan.b, but in std_msgs/Float64: it has no field 'b'; its value stays unknown"


def test_a_false_rule_with_a_field_it_cannot_read_is_an_error_of_its_entity():
    spec = check_text(SPEC)
    topics = {"/scan": {"messages": 5, "errors": [ERR], "type": "std_msgs/Float64"}}
    laser, _ = status.build(spec, {"laser.protective": False}, [], topics, {}, {}, {"master": "connected"})
    assert laser.level == status.ERROR and laser.message == f"DATA ERROR: {ERR}", laser
    fine, _ = status.build(spec, {"laser.protective": False}, [], {"/scan": {"messages": 5, "errors": []}}, {}, {},
                           {"master": "connected"})
    assert fine.level == status.OK


def test_a_stop_held_for_rules_a_reload_removed_makes_the_monitor_warn():
    spec = check_text(SPEC)
    held = "stop (behaviour 1, line 22, latched before the reload or clock jump)"
    _, mon = status.build(spec, {"laser.protective": False}, [], {}, {}, {},
                          {"master": "connected", status.HELD[0]: held})
    assert mon.level == status.WARN and f"HOLDING until ~reset: {held}" in mon.message
    _, calm = status.build(spec, {"laser.protective": False}, [], {}, {}, {}, {"master": "connected"})
    assert calm.level == status.OK and "HOLDING" not in calm.message


def test_a_mere_type_change_is_no_error_of_a_rule_it_leaves_known():
    """docs/monitor.md: a topic that changes type, when its new type has every field, is no error."""
    spec = check_text("entity base { rules: fast: topic /speed.data > 2.0; }\n")
    topics = {"/speed": {"messages": 5, "errors": ["changed type from std_msgs/Float64 to std_msgs/Float32"]}}
    base, _ = status.build(spec, {"base.fast": True}, [], topics, {}, {}, {"master": "connected"})
    assert base.level == status.WARN and base.message == "violated: fast", base
    base, _ = status.build(spec, {"base.fast": False}, [], topics, {}, {}, {"master": "connected"})
    assert base.level == status.OK, base


def test_latches_restored_at_start_make_the_monitor_warn():
    spec = check_text(SPEC)
    restored = "stop (behaviour 1 (line 3) of the last run)"
    _, mon = status.build(spec, {"laser.protective": False}, [], {}, {}, {},
                          {"master": "connected", status.HELD[1]: restored})
    assert mon.level == status.WARN and f"HOLDING until ~reset: {restored}" in mon.message
