"""Issue 13 (2): relative, absolute and ~private spellings of one topic resolve once, by ROS
rules, to one subscription and one value."""
import pytest
from rosharness import TWIST, first, spec

pytestmark = [pytest.mark.ros, pytest.mark.slow]


def test_age_of_a_relative_name_beside_fields_of_the_absolute_name_is_one_topic(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, "entity a { rules:\n  silent: age(topic cmd_vel) > 0.5 s;\n"
                                     "  fast: topic /cmd_vel.linear.x > 1;\n  quiet: age(topic ~ping) > 0.5 s;\n}\n"
                                     "if (a.silent or a.quiet) then { brake; }\nif (a.fast) then { stop; }\n"))
    rec = ros.probe({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}, {"topic": "/safety_cmd", "type": TWIST}],
                     "advertise": [{"topic": "/cmd_vel", "type": TWIST}, {"topic": "/rubass/ping", "type": "std_msgs/Empty"}],
                     "steps": [{"wait_subscribers": "/cmd_vel"}, {"wait_subscribers": "/rubass/ping"},
                               {"wait_publishers": "/brake"}, {"sleep": 0.3}, {"mark": "flowing"}]
                     + [{"publish": "/cmd_vel", "msg": {"linear": {"x": 0.2}}}, {"publish": "/rubass/ping"},
                        {"sleep": 0.1}] * 20
                     + [{"mark": "fast"}, {"publish": "/cmd_vel", "msg": {"linear": {"x": 2.0}}},
                        {"publish": "/rubass/ping"}, {"wait": "/safety_cmd", "timeout": 3}]}, timeout=60)
    flowing = next(r["wall"] for r in rec if r.get("name") == "flowing")
    assert not [r for r in rec if r["kind"] == "recv" and r["topic"] == "/brake" and r["wall"] > flowing + 0.3], \
        "messages flow on /cmd_vel and ~ping: 'age(topic cmd_vel)' and 'age(topic ~ping)' must see them\n" + ros.log(mon)
    assert first(rec, "recv", "/safety_cmd") is not None, ros.log(mon)
    import rosgraph
    state = rosgraph.Master("/t", master_uri=ros.env["ROS_MASTER_URI"]).getSystemState()
    subs = {t: n for t, n in state[1]}
    assert "/rubass" in subs["/cmd_vel"] and "cmd_vel" not in subs and "/rubass/ping" in subs
