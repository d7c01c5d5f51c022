"""docs/actions.md §Priorities: a reload that changes the message type of a topic the running
monitor publishes is rejected (rospy keeps the running publisher, of the old type, so the new
messages went out as garbage: a Twist subscriber got linear.x = 3.37e207 and the stop never
reached the base). The old rules and actions keep running; ~reload's answer and /diagnostics
say why, naming the topic, both types and the library place."""
import time

import pytest
import yaml
from rosharness import TWIST

pytestmark = [pytest.mark.ros, pytest.mark.slow]

STAMPED = "geometry_msgs/TwistStamped"
LIB = """actions:
  stop:
    plugin: publish
    topic: /safe
    type: {typ}
    message: {{}}
    rate: 20 Hz
    priority: 3
  crawl:
    plugin: limit
    input: {source}
    topic: /safe
    type: {typ}
    linear_x: [-0.1 m/s, {top} m/s]
    priority: 1
"""
SPEC = ('import "lib.yaml";\naction primitive stop, crawl;\n'
        "entity e { rules: near: topic /near.data > 1; far: topic /far.data > 1; }\n"
        "if (e.near) then { crawl; }\nif (e.far) then { stop; }\n")


def crawl_output(ros, listen_type):
    """Commands on /nav_vel (linear.x 1.0) with crawl active: what a `listen_type` subscriber of /safe gets."""
    return ros.probe({"listen": [{"topic": "/safe", "type": listen_type}],
                      "advertise": [{"topic": "/near", "type": "std_msgs/Float64"}, {"topic": "/nav_vel", "type": TWIST}],
                      "steps": [{"wait_subscribers": "/near"}, {"wait_subscribers": "/nav_vel"}, {"sleep": 0.5},
                                {"publish": "/near", "msg": {"data": 2.0}}, {"sleep": 0.2},
                                {"publish": "/nav_vel", "msg": {"linear": {"x": 1.0}}, "repeat": 10, "period": 0.05},
                                {"sleep": 0.3}]})


def test_a_reload_changing_the_type_of_a_published_topic_is_rejected_and_the_old_actions_go_on(ros, tmp_path):
    lib = tmp_path / "lib.yaml"
    lib.write_text(LIB.format(typ=TWIST, source="/nav_vel", top="0.15"))
    (tmp_path / "s.rbs").write_text(SPEC)
    mon = ros.monitor(str(tmp_path / "s.rbs"))
    got = [r["msg"]["linear"]["x"] for r in crawl_output(ros, TWIST) if r["kind"] == "recv"]
    assert got and max(got) == pytest.approx(0.15), got  # crawl is active and clamps

    lib.write_text(LIB.format(typ=STAMPED, source="/nav_s", top="0.15"))
    time.sleep(0.1)
    out = ros.call("/rubass/reload")
    answer = yaml.safe_load(out.stdout)  # rosservice folds long lines
    assert answer["success"] is False, out.stdout + ros.log(mon)
    text = answer["message"]
    assert "rejected, the previous rules keep running" in text
    assert f"lib.yaml:5:11: error: action 'stop': publishes {STAMPED} on /safe, but the running monitor " \
           f"publishes {TWIST} there" in text, text
    assert "restart the monitor to change the type of /safe" in text
    assert "action 'crawl': publishes" in text  # every action that would change it, each at its place
    assert "topic types do not match" not in ros.log(mon)

    # the old actions keep protecting: a Twist subscriber still gets crawl's clamped commands, not garbage
    got = [r["msg"]["linear"]["x"] for r in crawl_output(ros, TWIST) if r["kind"] == "recv"]
    assert got and max(got) == pytest.approx(0.15), got
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"sleep": 2.5}]})
    mon_status = [{kv["key"]: kv["value"] for kv in s["values"]}
                  for r in rec if r["kind"] == "recv" for s in r["msg"]["status"] if s["name"] == "rubass: monitor"]
    assert mon_status, rec
    assert mon_status[-1]["rejected reloads"] == "1"
    assert "action 'stop': publishes geometry_msgs/TwistStamped on /safe" in mon_status[-1]["last reload error"]

    # a reload keeping the types still goes through (the new range applies)
    lib.write_text(LIB.format(typ=TWIST, source="/nav_vel", top="0.05"))
    time.sleep(0.1)
    out = ros.call("/rubass/reload")
    assert "success: True" in out.stdout, out.stdout + ros.log(mon)
    got = [r["msg"]["linear"]["x"] for r in crawl_output(ros, TWIST) if r["kind"] == "recv"]
    assert got and max(got) == pytest.approx(0.05), got
