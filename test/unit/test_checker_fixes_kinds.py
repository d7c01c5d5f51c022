"""The checker against a system model: a string or a message inside any/all/count/min/max is the
same error as outside them (issue 15); warnings are kept beside errors; one error per mistake.
Pure: the model is a model file written out here (custom types, nothing installed is read)."""
import pytest

from rubass.lang import SpecError
from rubass.lang.loader import check_source
from rubass.lang.modelfile import parse_model
from rubass.lang.source import Source

LIB = "actions:\n  warn: {plugin: log}\n"
HEAD = 'import "actions.yaml";\naction primitive warn;\n'
MODEL = """\
rubass_model: 1
topics:
  /js: t_msgs/Joints
  /diag: t_msgs/Diags
  /bms: t_msgs/Pack
  /v: t_msgs/Vel
definitions:
  t_msgs/Joints: |
    string[] name
    float64[] position
    bool[] ok
  t_msgs/Status: |
    byte level
    string name
  t_msgs/Diags: |
    t_msgs/Status[] status
  t_msgs/Cell: |
    float32 voltage
  t_msgs/Pack: |
    t_msgs/Cell[] cells
    float32[4] temps
  t_msgs/Vel: |
    float64 x
"""


@pytest.fixture
def model():
    m, diags = parse_model(Source("robot.yaml", MODEL))
    assert m is not None, diags
    return m


def _check(tmp_path, model, body):
    (tmp_path / "actions.yaml").write_text(LIB)
    path = tmp_path / "s.rbs"
    text = HEAD + body
    path.write_text(text)
    return check_source(Source(str(path), text), model=model)


def diags(tmp_path, model, body):
    """[(line, col, severity, message)] of everything a spec with errors reports, in order."""
    with pytest.raises(SpecError) as info:
        _check(tmp_path, model, body)
    return [(d.span.line, d.span.col, d.severity, d.message) for d in info.value.in_order()]


def errors(tmp_path, model, body):
    return [(l, c, m) for l, c, s, m in diags(tmp_path, model, body) if s == "error"]


STRING_NUMBER = "'==' compares a string with a number"
NOT_A_NUMBER = "'>' needs a number, not a string"


@pytest.mark.parametrize("rule, col, message", [
    # the scalar case, as it always was: the array cases below must say the same
    ("topic /js.name[0] == 1", 26, STRING_NUMBER),
    ("any(topic /js.name[*] == 1)", 30, STRING_NUMBER),
    ("all(topic /js.name[0:2] == 1)", 32, STRING_NUMBER),
    ("count(topic /js.name[*] > 0) >= 0", 14, NOT_A_NUMBER),
    ("any(topic /diag.status[*].name == 2)", 39, STRING_NUMBER),
    ("max(topic /js.name) > 0", 12, "max() needs a number, not a string"),
    ("min(topic /diag.status[*].name) >= 0", 12, "min() needs a number, not a string"),
    ("max(topic /js.ok[*]) > 0", 12, "max() needs a number, not a condition"),
    ("any(topic /js.ok[*] > 0)", 12, "'>' needs a number, not a condition"),
])
def test_strings_and_conditions_in_array_terms_are_errors_at_their_place(tmp_path, model, rule, col, message):
    got = errors(tmp_path, model, f"r: if ({rule}) then {{ warn; }}\n")
    assert got == [(3, col, message)]


MESSAGE = ("'topic /diag.status[*]' is a message, not a value: it is a t_msgs/Status (fields: level, name); "
           "name one of its fields")


@pytest.mark.parametrize("rule, col, message", [
    ("topic /diag.status[0] == 1", 8, MESSAGE.replace("[*]", "[0]")),  # the scalar case
    ("any(topic /diag.status[*] == 2)", 12, MESSAGE),
    ("min(topic /diag.status[*]) < 3", 12, MESSAGE),
    ("count(topic /diag.status[*] > 1) > 0", 14, MESSAGE),
    ("max(topic /bms.cells[*]) < 3 V", 12,
     "'topic /bms.cells[*]' is a message, not a value: it is a t_msgs/Cell (fields: voltage); name one of its fields"),
    ("max(topic /bms.cells) < 3 V", 12,
     "'topic /bms.cells' is an array of messages (t_msgs/Cell[]), not of values: name one of their fields, "
     "e.g. 'topic /bms.cells[*].FIELD'"),
])
def test_a_message_used_as_a_value_is_an_error_inside_quantifiers_too(tmp_path, model, rule, col, message):
    assert errors(tmp_path, model, f"r: if ({rule}) then {{ warn; }}\n") == [(3, col, message)]


@pytest.mark.parametrize("rule", [
    "len(topic /diag.status) > 2",  # the length of an array of messages is a number
    "len(topic /js.name) > 2",
    "any(topic /diag.status[*].level >= 2)",
    "max(topic /bms.cells[*].voltage) < 4.2 V",
    "any(topic /js.name[*] == \"wheel\")",
    "all(topic /js.ok[*])",
    "count(topic /js.position[*] > 1) < 2",
])
def test_what_fits_the_types_still_checks(tmp_path, model, rule):
    assert _check(tmp_path, model, f"r: if ({rule}) then {{ warn; }}\n") is not None


def test_all_array_errors_of_a_spec_in_one_run(tmp_path, model):
    body = ("entity j { rules:\n  a: any(topic /js.name[*] == 1);\n  b: count(topic /js.name[*] > 0) >= 0;\n"
            "  c: max(topic /js.name) > 0;\n  d: min(topic /diag.status[*]) < 3;\n}\n"
            "if (j.a or j.b or j.c or j.d) then { warn; }\n")
    assert [(l, m) for l, _, m in errors(tmp_path, model, body)] == [
        (4, STRING_NUMBER), (5, NOT_A_NUMBER), (6, "max() needs a number, not a string"), (7, MESSAGE)]


def test_abs_of_a_string_is_one_error(tmp_path, model):
    assert errors(tmp_path, model, "if (abs(topic /js.name[0]) > 1) then { warn; }\n") == [
        (3, 9, "abs() needs a number, not a string")]
    assert errors(tmp_path, None, 'if (abs("a") > 1 or min("b", 2) > 1) then { warn; }\n') == [
        (3, 9, "abs() needs a number, not a string"), (3, 25, "min() needs a number, not a string")]


STAMP = ("stamp_age(topic /v) is always unknown: the topic's type has no header.stamp "
         "(use age() for the time since its last message)")


def test_the_stamp_age_warning_is_reported_beside_the_errors(tmp_path, model):
    body = "if (stamp_age(topic /v) > 1 s) then { warn; }\nif (topic /v.x == \"a\") then { warn; }\n"
    assert diags(tmp_path, model, body) == [
        (3, 15, "warning", STAMP), (4, 16, "error", "'==' compares a number with a string")]
    with pytest.raises(SpecError) as info:
        _check(tmp_path, model, body)
    assert [d.severity for d in info.value.diagnostics] == ["error"]  # readers of the errors see errors only
    text = info.value.render()
    assert "warning: stamp_age(topic /v) is always unknown" in text and text.index("warning") < text.index("error")


def test_without_errors_the_warning_stays_on_the_checked_spec(tmp_path, model):
    checked = _check(tmp_path, model, "if (stamp_age(topic /v) > 1 s) then { warn; }\n")
    assert [w.message for w in checked.warnings] == [STAMP]


def test_the_recordings_joint_names_are_strings_inside_quantifiers(tmp_path):
    """The tester's js.rbs, with the types of the shared recording (`check --bag`)."""
    from conftest import shared_path
    from rubass.ros.model_sources import bag_model  # reads the bag with rubass's own reader: no ROS

    model = bag_model(shared_path("data", "turtlebot3_sim.bag"))
    body = ("entity j { rules:\n  named: any(topic /joint_states.name[*] == 1);\n"
            "  any_hi: count(topic /joint_states.name[*] > 0) >= 0;\n  mx: max(topic /joint_states.name) > 0;\n}\n"
            "if (j.named or j.any_hi or j.mx) then { warn; }\n")
    assert errors(tmp_path, model, body) == [
        (4, 42, STRING_NUMBER), (5, 17, NOT_A_NUMBER), (6, 11, "max() needs a number, not a string")]


def test_the_live_monitor_finds_the_same_error_once_the_types_are_known(tmp_path):
    """rubass/ros/livecheck.py checks the running spec with the types the topics carry: same checker."""
    from rubass.ros.livecheck import live_errors  # pure: no rospy

    spec = _check(tmp_path, None, "r: if (any(topic /js.name[*] == 1) or max(topic /js.name) > 0) then { warn; }\n")
    got = live_errors(spec, [], {"/js": ("t_msgs/Joints", "string[] name\nfloat64[] position\n")})
    assert [e.splitlines()[0].split(": ", 1)[1] for e in got] == [
        "error: '==' compares a string with a number", "error: max() needs a number, not a string"]
