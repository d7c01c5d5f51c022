"""The monitor's /diagnostics entries, built from plain data (no ROS)."""
from rubass.lang import check_text
from rubass.actions import status

SPEC = "entity base { rules: fast: topic /cmd_vel.linear.x > 1; }\n"


def monitor_entry(failing=(), **monitor):
    spec = check_text(SPEC)
    entries = status.build(spec, {"base.fast": False}, [], {}, {}, {}, monitor, failing)
    return entries[-1]


def test_a_healthy_monitor_is_ok():
    e = monitor_entry(master="connected")
    assert e.level == status.OK and "master" not in e.message


def test_an_unreachable_master_turns_the_monitor_warn_and_says_so():
    e = monitor_entry(master="unreachable for 3.2 s")
    assert e.level == status.WARN and "master unreachable for 3.2 s" in e.message


def test_a_rejected_reload_stays_error_whatever_the_master():
    e = monitor_entry(master="unreachable for 1.0 s", **{"last reload error": "s.rbs:1:2: error: x"})
    assert e.level == status.ERROR


def test_an_overloaded_monitor_is_error_and_names_the_fail_safe_actions():
    e = monitor_entry(master="connected", overloaded="running stop")
    assert e.level == status.ERROR and "OVERLOADED, dropping messages: running stop" in e.message


def test_an_overload_by_late_reading_says_so_and_late_reading_alone_is_a_warning():
    e = monitor_entry(master="connected", overloaded="running stop",
                      **{"overload cause": "reading its topics 0.84 s late"})
    assert e.level == status.ERROR and "OVERLOADED, reading its topics 0.84 s late: running stop" in e.message
    late = "0.84 s (messages waited that long in the sockets' buffers: the monitor cannot keep up)"
    e = monitor_entry(master="connected", **{"read late": late})
    assert e.level == status.WARN and f"(READ LATE: {late})" in e.message
    assert monitor_entry(master="connected", **{"read late": "no"}).level == status.OK


def test_an_action_failure_is_error_only_until_a_later_attempt_succeeds():
    """A stop that reached no subscriber once, then did: the count stays on record, the level is OK."""
    from rubass.actions.base import ActionStats
    error = "start: OSError: no node subscribes to /x"
    stats = {"stop2": ActionStats(failures=3, last_error=error, failing="start"), "warn": ActionStats(calls=2)}
    failing = monitor_entry(status.failing_of(stats), **{"failed action attempts": 3, "action stop2": error})
    assert failing.level == status.ERROR
    assert "ACTION FAILING: stop2: start: OSError: no node subscribes to /x" in failing.message
    stats["stop2"] = ActionStats(failures=3, last_error=status.RESOLVED + error, failing="")  # a later success
    resolved = monitor_entry(status.failing_of(stats),
                             **{"failed action attempts": 3, "action stop2": status.RESOLVED + error})
    assert resolved.level == status.OK and "FAILING" not in resolved.message
    assert ("failed action attempts", "3") in resolved.values


def test_an_action_named_failures_is_not_confused_with_the_count_of_failures():
    """Its error is its own value, the count another; failing or not is the runner's state, not text."""
    e = monitor_entry([("failures", "start: OSError: away")],
                      **{"failed action attempts": 2, "action failures": "start: OSError: away"})
    assert e.level == status.ERROR and "ACTION FAILING: failures: start: OSError: away" in e.message
    assert ("failed action attempts", "2") in e.values and ("action failures", "start: OSError: away") in e.values


def test_a_type_change_shows_the_rule_and_field_it_breaks_first():
    """Acceptance finding: 'DATA ERROR: changed type from … (and 2 more)' hid which rule reads what."""
    spec = check_text("entity a { rules: n: topic /x.linear.x > 1; }\n")
    topic = {"messages": 3, "errors": ["rule 'a.n' reads /x.linear.x, but in std_msgs/String: 'linear' …",
                                       "changed type from geometry_msgs/Twist to std_msgs/String"]}
    entries = status.build(spec, {"a.n": None}, [], {"/x": topic}, {}, {}, {})
    entity = next(e for e in entries if e.name == "rubass: a")
    assert entity.message.startswith("DATA ERROR: rule 'a.n' reads /x.linear.x"), entity.message
    assert entity.message.endswith("(and 1 more)")
