"""Issue 13 (8): a field that cannot be read as the rule needs makes /diagnostics ERROR naming the
rule and the field, and runs ~error_actions while the error lasts."""
import time

import pytest
from rosharness import first, records, spec, wait_log

pytestmark = [pytest.mark.ros, pytest.mark.slow]


def diagnostics(ros):
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"sleep": 1.5}]})
    return [s for r in rec if r["kind"] == "recv" for s in r["msg"]["status"]]


def test_an_array_used_as_a_number_is_an_error_naming_rule_and_field_and_runs_the_error_actions(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, "entity a { rules: n: topic /arr.data > 1; }\nif (a.n) then { stop; }\n"),
                      error_actions="brake")
    rec = ros.probe({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}],
                     "advertise": [{"topic": "/arr", "type": "std_msgs/Float64MultiArray"}],
                     "steps": [{"wait_subscribers": "/arr"}, {"wait_publishers": "/brake"}, {"sleep": 0.3},
                               {"publish": "/arr", "msg": {"data": [5.0, 6.0]}}, {"wait": "/brake", "timeout": 3}]})
    assert first(rec, "recv", "/brake") is not None, ros.log(mon)
    statuses = diagnostics(ros)
    entity = next(s for s in statuses if s["name"] == "rubass: a")
    assert entity["level"] == 2 and "a.n" in entity["message"] and "/arr.data" in entity["message"], entity
    assert "array" in entity["message"]
    monitor = next(s for s in statuses if s["name"] == "rubass: monitor")
    assert monitor["level"] == 2 and "DATA ERROR" in monitor["message"], monitor
    wait_log(mon, ros, "running brake (~error_actions) while it lasts")


def test_a_missing_field_runs_the_error_actions_until_the_topic_has_it_again(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, "entity a { rules: r: topic /x.linear.x > 1; }\nif (a.r) then { stop; }\n"),
                      error_actions="brake")
    brake = ros.probe_bg({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}],
                          "steps": [{"sleep": 0.5}, {"mark": "ready"}, {"sleep": 8.0}]}, name="brake")
    assert '"ready"' in brake.stdout.readline()
    ros.probe({"advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],  # no field 'linear'
               "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.3}, {"publish": "/x", "msg": {"data": 1.0}},
                         {"sleep": 1.0}]})
    wait_log(mon, ros, "running brake (~error_actions)")
    ros.probe({"advertise": [{"topic": "/x", "type": "geometry_msgs/Twist"}],  # the right type again
               "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.3}, {"publish": "/x", "msg": {"linear": {"x": 0.1}}},
                         {"sleep": 0.3}]})
    wait_log(mon, ros, "the data error is gone: releasing brake")
    released = time.time()
    got = [r["wall"] for r in records(brake) if r["kind"] == "recv"]
    assert got, "the brake ran while the field could not be read"
    assert not [w for w in got if w > released + 0.3], "and stopped once it could"


def test_a_string_compared_with_a_number_is_a_data_error_not_a_silent_unknown(ros, tmp_path):
    """Acceptance finding: `topic /bump.data > 0` on a std_msgs/String stayed unknown with no
    error, no reason and no ~error_actions."""
    mon = ros.monitor(spec(tmp_path, "entity a { rules: hit: topic /bump.data > 0; }\nif (a.hit) then { stop; }\n"),
                      error_actions="brake")
    rec = ros.probe({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}],
                     "advertise": [{"topic": "/bump", "type": "std_msgs/String"}],
                     "steps": [{"wait_subscribers": "/bump"}, {"wait_publishers": "/brake"}, {"sleep": 0.3},
                               {"publish": "/bump", "msg": {"data": "5"}}, {"wait": "/brake", "timeout": 3}]})
    assert first(rec, "recv", "/brake") is not None, ros.log(mon)
    statuses = diagnostics(ros)
    entity = next(s for s in statuses if s["name"] == "rubass: a")
    assert entity["level"] == 2 and "a.hit" in entity["message"] and "is a string" in entity["message"], entity
    wait_log(mon, ros, "'data' is a string, and the spec uses it as a number")
