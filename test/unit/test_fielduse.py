"""What a spec needs of the fields it reads as one value, and the live type check against it:
a string or a bool computed with as a number, or a number or a string used as true/false, would
only ever be unknown (acceptance finding: a String on a topic compared with 0 was silently unknown)."""
import pytest

from rubass.lang import check_text
from rubass.lang.fielduse import CONDITION, NUMBER, field_needs

SPEC = """const L = 2 m;
entity e { rules:
  a: topic /a.data > 0;
  b: topic /b.flag;
  c: not topic /c.flag and topic /c2.x == 3;
  d: (abs(topic /d.v) > L) for 1 s;
  s: topic /s.name == "x";
  n: topic /n.ok == true;
  m: min(topic /m.r[0:3]) < 1;
  q: any(topic /q.s[*].level >= 2);
  r: rate(topic /r.p) > 1;
  z: inside(topic /z.x, topic /z.y, polygon((0 m, 0 m), (1 m, 0 m), (1 m, 1 m)));
  l: latch(topic /l.a, topic /l.b);
  i: topic /i.arr[0] - 1 > 0;
}
"""


def test_each_field_read_as_one_value_has_what_the_spec_does_with_it():
    spec = check_text(SPEC)
    assert field_needs([r.expr for r in spec.rules]) == {
        "/a": {("data",): NUMBER}, "/b": {("flag",): CONDITION}, "/c": {("flag",): CONDITION},
        "/c2": {("x",): NUMBER}, "/d": {("v",): NUMBER}, "/n": {("ok",): CONDITION},
        "/r": {("p",): NUMBER}, "/z": {("x",): NUMBER, ("y",): NUMBER},
        "/l": {("a",): CONDITION, ("b",): CONDITION}, "/i": {("arr", 0): NUMBER},
    }  # a string compared with a string, array terms and quantifiers: nothing to check


@pytest.mark.parametrize("type_,need,problem", [
    ("std_msgs/String", NUMBER, "'data' is a string, and the spec uses it as a number"),
    ("std_msgs/Bool", NUMBER, "'data' is a bool, and the spec uses it as a number"),
    ("std_msgs/Float64", CONDITION, "'data' is a float64, and the spec uses it as a condition (true or false): "
                                    "compare it, e.g. 'data > 0'"),
    ("std_msgs/String", CONDITION, "compare it, e.g. 'data == \"…\"'"),
    ("std_msgs/Int32", NUMBER, None), ("std_msgs/Bool", CONDITION, None), ("std_msgs/Float64", None, None),
    ("std_msgs/String", None, None),
])
def test_the_live_type_is_checked_against_the_need(type_, need, problem):
    pytest.importorskip("genpy")  # message classes need ROS
    import roslib.message

    from rubass.ros.msgtypes import check_path

    got = check_path(roslib.message.get_message_class(type_), ("data",), True, need)
    assert (got is None) if problem is None else (problem in got), got
