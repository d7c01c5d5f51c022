"""Action libraries against message and service definitions (pure: definitions written out)."""
import pytest

from rubass.lang.libcheck import check_library_types, check_publish_topics, library_types
from rubass.lang.library import parse_library
from rubass.lang.msgdef import Registry, parse_msg, parse_srv
from rubass.lang.source import Source, SourceSet


def registry():
    r = Registry()
    r.add(parse_msg("geometry_msgs/Twist", "Vector3 linear\nVector3 angular\n"))
    r.add(parse_msg("geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"))
    r.add(parse_msg("std_msgs/Header", "uint32 seq\ntime stamp\nstring frame_id\n"))
    r.add(parse_msg("my_msgs/Board", "Header header\nuint8 mode\nbool brake\nstring why\nint16[3] pwm\n"
                                     "float32[] limits\nuint8[] raw\n"))
    req, resp = parse_srv("std_srvs/SetBool", "bool data\n---\nbool success\nstring message\n")
    r.add_service("std_srvs/SetBool", req, resp)
    return r


def check(text, topics=None):
    sources = SourceSet()
    src = Source("lib.yaml", text)
    sources.add(src)
    actions, diags = parse_library(src)
    assert diags == []
    out = check_library_types(actions, sources, registry(), "the test registry")
    if topics is not None:
        out += check_publish_topics(actions, sources, topics, "the test model")
    return [f"{d.span.line}:{d.span.col}: {d.message}" for d in out]


GOOD = """actions:
  stop:
    plugin: publish
    topic: /cmd_vel
    type: geometry_msgs/Twist
    message: {linear: {x: 0, y: 0.0}, angular: [0, 0, 0]}
  board:
    plugin: publish
    topic: /board
    type: my_msgs/Board
    message: {header: {stamp: {secs: 1, nsecs: 0}, frame_id: base}, mode: 255, brake: true, why: stop,
              pwm: [0, -3, 4], limits: [0.5, 1], raw: "\\x01"}
    on_release: {brake: false}
  brake_srv: {plugin: service, service: /brake, type: std_srvs/SetBool, request: {data: true}}
  note: {plugin: log, message: hi}
"""


def test_a_library_that_fits_its_types():
    assert check(GOOD) == []
    assert library_types(parse_library(Source("l.yaml", GOOD))[0]) == (
        ["geometry_msgs/Twist", "my_msgs/Board"], ["std_srvs/SetBool"])


@pytest.mark.parametrize("fragment,expected", [
    ("type: geometry_msgs/Twst\n    message: {}",
     "5:11: action 'a': unknown message type 'geometry_msgs/Twst' (not in the test registry); did you mean 'geometry_msgs/Twist'?"),
    ("type: geometry_msgs/Twist\n    message: {linear: {q: 1}}",
     "6:24: action 'a': geometry_msgs/Vector3 has no field 'q' (its fields: x, y, z)"),
    ("type: geometry_msgs/Twist\n    message: {liner: {x: 1}}",
     "6:15: action 'a': geometry_msgs/Twist has no field 'liner'; did you mean 'linear'? (its fields: linear, angular)"),
    ("type: geometry_msgs/Twist\n    message: {linear: {x: fast}}",
     "6:27: action 'a': 'message.linear.x' is a float64: give a number, got 'fast'"),
    ("type: geometry_msgs/Twist\n    message: {linear: 3}",
     "6:23: action 'a': 'message.linear' must be a mapping of geometry_msgs/Vector3 fields (x, y, z)"),
    ("type: geometry_msgs/Twist\n    message: {angular: [0, 0]}",
     "6:24: action 'a': 'message.angular' lists 2 values, geometry_msgs/Vector3 has 3 fields (x, y, z)"),
    ("type: my_msgs/Board\n    message: {mode: 256}",
     "6:21: action 'a': 'message.mode' is a uint8: the value must be from 0 to 255, got 256"),
    ("type: my_msgs/Board\n    message: {mode: 1.5}",
     "6:21: action 'a': 'message.mode' is a uint8: give a whole number from 0 to 255, got 1.5"),
    ("type: my_msgs/Board\n    message: {brake: 2}",
     "6:22: action 'a': 'message.brake' is a bool: give true or false, got 2"),
    ("type: my_msgs/Board\n    message: {why: 3}",
     "6:20: action 'a': 'message.why' is a string: give a string (quote it), got 3"),
    ("type: my_msgs/Board\n    message: {pwm: [1, 2]}",
     "6:20: action 'a': 'message.pwm' is an int16[3]: give exactly 3 values, got 2"),
    ("type: my_msgs/Board\n    message: {limits: 3}",
     "6:23: action 'a': 'message.limits' is an array (float32[]): give a list, got 3"),
    ("type: my_msgs/Board\n    message: {limits: [1, x]}",
     "6:27: action 'a': 'message.limits[1]' is a float32: give a number, got 'x'"),
    ("type: my_msgs/Board\n    message: {header: {stamp: now}}",
     "6:31: action 'a': 'message.header.stamp' is a time: give {secs: S, nsecs: N} or a whole number of "
     "nanoseconds, got 'now'"),
    # values genpy cannot serialise, which the monitor refused at start with no place (acceptance sweep)
    ("type: my_msgs/Board\n    message: {limits: [1.0e+39]}",
     "6:24: action 'a': 'message.limits[0]' is a float32: too large for a float32 (at most 3.4028235e+38), got 1e+39"),
    ("type: geometry_msgs/Twist\n    message: {linear: {x: 1" + "0" * 400 + "}}",
     "6:27: action 'a': 'message.linear.x' is a float64: too large for a float64 (at most 1.7976931e+308), got 1"
     + "0" * 400),
    ("type: my_msgs/Board\n    message: {header: {stamp: {secs: -1}}}",
     "6:38: action 'a': 'message.header.stamp.secs' is a uint32: give a whole number from 0 to 4294967295, got -1"),
    ("type: my_msgs/Board\n    message: {header: {stamp: -5}}",
     "6:31: action 'a': 'message.header.stamp' is a time: a whole number of nanoseconds must be from 0 to "
     "4294967295000000000, got -5"),
    ("type: my_msgs/Board\n    on_release: {brake: off, mood: 1}",
     "6:30: action 'a': my_msgs/Board has no field 'mood'; did you mean 'mode'? (its fields: header, mode, brake, why, pwm, limits, raw)"),
])
def test_publish_errors_point_at_the_yaml(fragment, expected):
    text = f"actions:\n  a:\n    plugin: publish\n    topic: /t\n    {fragment}\n"
    assert check(text) == [expected]


def test_service_errors():
    text = "actions:\n  s: {plugin: service, service: /b, type: std_srvs/SetBool, request: {dat: true}}\n" \
           "  t: {plugin: service, service: /b, type: std_srvs/SetBol}\n"
    assert check(text) == [
        "2:71: action 's': std_srvs/SetBoolRequest has no field 'dat'; did you mean 'data'? (its fields: data)",
        "3:43: action 't': unknown service type 'std_srvs/SetBol' (not in the test registry); "
        "did you mean 'std_srvs/SetBool'?"]


def test_publish_topic_of_another_type_in_the_model():
    assert check(GOOD, {"/cmd_vel": "geometry_msgs/TwistStamped", "/board": "my_msgs/Board"}) == [
        "5:11: action 'stop': publishes geometry_msgs/Twist on /cmd_vel, which carries "
        "geometry_msgs/TwistStamped in the test model: its subscribers would refuse the connection"]


def test_values_a_merge_key_brings_in_are_checked_at_their_place():
    """`brake: {<<: *stop, type: std_msgs/Float64}` inherits stop's Twist message: the monitor refused it
    at start, `rubass check` said ok (acceptance sweep)."""
    text = ("actions:\n  stop: &s\n    plugin: publish\n    topic: /t\n    type: geometry_msgs/Twist\n"
            "    message: {linear: {x: 0}}\n  board: {<<: *s, topic: /b, type: my_msgs/Board}\n"
            "  slow: {<<: *s, topic: /s, message: {<<: {linear: {x: 0.1}}, angular: {z: 0}}}\n")
    assert check(text) == ["6:15: action 'board': my_msgs/Board has no field 'linear' (its fields: header, mode, "
                           "brake, why, pwm, limits, raw)"]
