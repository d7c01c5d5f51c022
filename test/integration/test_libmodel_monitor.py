"""The monitor refuses what `rubass check` refuses in an action library (acceptance findings):
two message types on one topic, a standard-library plugin, a key written twice; at start and
at reload, the old rules keeping running."""
import pytest
import yaml

from rosharness import wait_log

pytestmark = pytest.mark.ros

SPEC = ('import "lib.yaml";\naction primitive a, b;\n'
        "entity x { rules: r: topic /x.data > 1; }\nif (x.r) then { a; b; }\n")
GOOD = ("actions:\n  a: {plugin: publish, topic: /o, type: geometry_msgs/Twist, priority: 2}\n"
        "  b: {plugin: publish, topic: /o, type: geometry_msgs/Twist, priority: 1}\n")


CONFLICT = GOOD.replace("  b: {plugin: publish,", "  b: {plugin: limit, input: /nav, linear_x: [0, 1 m/s],").replace(
    "type: geometry_msgs/Twist, priority: 1", "type: geometry_msgs/TwistStamped, priority: 1")
TYPES = "action 'b': publishes geometry_msgs/TwistStamped on /o, but action 'a' (line 2) publishes geometry_msgs/Twist"


def test_two_types_on_one_topic_are_refused_at_start(ros, tmp_path):
    lib = tmp_path / "lib.yaml"
    lib.write_text(CONFLICT)
    (tmp_path / "s.rbs").write_text(SPEC)
    mon = ros.monitor(str(tmp_path / "s.rbs"))  # up, enforcing nothing
    wait_log(mon, ros, f"{lib}:3:")
    log = ros.log(mon)
    assert f"{lib}:3:74: error: " + TYPES in log, log
    assert "Traceback" not in log


def test_library_errors_are_rejected_at_reload(ros, tmp_path):
    lib = tmp_path / "lib.yaml"
    lib.write_text(GOOD)
    (tmp_path / "s.rbs").write_text(SPEC)
    mon = ros.monitor(str(tmp_path / "s.rbs"))
    lib.write_text(CONFLICT)
    out = yaml.safe_load(ros.call("/rubass/reload").stdout)
    assert out["success"] is False and TYPES in out["message"], out
    lib.write_text(GOOD.replace("priority: 1}", "priority: 1, priority: 0}\n  c: {plugin: json:JSONDecoder}"))
    out = yaml.safe_load(ros.call("/rubass/reload").stdout)
    assert out["success"] is False and "key 'priority' is written twice" in out["message"], out
    assert "plugin module 'json' is part of Python's standard library" in out["message"], out
    assert "Traceback" not in ros.log(mon)
