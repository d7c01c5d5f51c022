"""Slices of fixed-size arrays against a system model (docs/model.md): one that selects no element
is an error, one that runs past the end a warning; and a dimensionless field is 'a plain number'.
Pure: the model is a model file written out here."""
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
  /odom: t_msgs/Odom
  /pose: geometry_msgs/Pose
definitions:
  t_msgs/Odom: |
    float64[36] covariance
    float64[] ranges
    t_msgs/Cell[4] cells
  t_msgs/Cell: |
    float32 voltage
  geometry_msgs/Pose: |
    geometry_msgs/Point position
    geometry_msgs/Quaternion orientation
  geometry_msgs/Point: |
    float64 x
    float64 y
    float64 z
  geometry_msgs/Quaternion: |
    float64 x
    float64 y
    float64 z
    float64 w
"""
COV = "'covariance', a float64[36]: its indices are 0 to 35"


@pytest.fixture
def model():
    m, diags = parse_model(Source("robot.yaml", MODEL))
    assert m is not None, diags
    return m


def run(tmp_path, model, cond):
    """(errors, warnings) as (col, message) of `if (cond) then { warn; }` on line 3."""
    (tmp_path / "actions.yaml").write_text(LIB)
    text = HEAD + f"if ({cond}) then {{ warn; }}\n"
    (tmp_path / "s.rbs").write_text(text)
    try:
        checked = check_source(Source(str(tmp_path / "s.rbs"), text), model=model)
    except SpecError as exc:
        return ([(d.span.col, d.message) for d in exc.diagnostics],
                [(d.span.col, d.message) for d in exc.warnings])
    return [], [(d.span.col, d.message) for d in checked.warnings]


@pytest.mark.parametrize("term", ["[40:50]", "[36:]", "[-50:-40]", "[:-36]"])  # [5:2]: test_checker_resweep.py
def test_a_slice_that_selects_nothing_of_a_fixed_size_array_is_an_error(tmp_path, model, term):
    errors, _ = run(tmp_path, model, f"min(topic /odom.covariance{term}) > -1")
    assert errors == [(9, f"'covariance{term}' selects no element of {COV} (a slice is clipped to the array, "
                          "so this one is always empty)")]


def test_inside_a_quantifier_too_and_an_index_still_says_beyond(tmp_path, model):
    errors, _ = run(tmp_path, model, "any(topic /odom.covariance[40:50] > 1) or topic /odom.covariance[36] > 1")
    assert errors == [
        (9, f"'covariance[40:50]' selects no element of {COV} (a slice is clipped to the array, so this one is "
            "always empty)"),
        (47, f"'covariance[36]' is beyond the end of {COV}")]


@pytest.mark.parametrize("term, clipped, side", [("[30:40]", "[30:36]", "end"), ("[-40:]", "[0:36]", "start"),
                                                 ("[-40:2]", "[0:2]", "start")])
def test_a_slice_running_past_the_end_is_a_warning(tmp_path, model, term, clipped, side):
    errors, warnings = run(tmp_path, model, f"min(topic /odom.covariance{term}) > -1")
    assert errors == []
    assert warnings == [(9, f"'covariance{term}' runs past the {side} of {COV}; it is clipped to "
                            f"'covariance{clipped}'")]


@pytest.mark.parametrize("cond", [
    "min(topic /odom.covariance[0:36]) > -1", "max(topic /odom.covariance[-36:]) > 1",
    "any(topic /odom.covariance[*] > 1)", "max(topic /odom.covariance[35:]) > 1",
    "min(topic /odom.ranges[400:500]) > 1",  # variable length: nothing to say before it runs
    "any(topic /odom.cells[0:4].voltage < 3 V) and topic /odom.cells[3].voltage < 4",
])
def test_slices_inside_the_array_check_clean(tmp_path, model, cond):
    assert run(tmp_path, model, cond) == ([], [])


def test_a_slice_of_an_array_of_messages_is_checked_too(tmp_path, model):
    errors, _ = run(tmp_path, model, "max(topic /odom.cells[4:].voltage) > 1")
    assert errors == [(9, "'cells[4:]' selects no element of 'cells', a t_msgs/Cell[4]: its indices are 0 to 3 "
                          "(a slice is clipped to the array, so this one is always empty)")]


def test_a_quaternion_component_with_an_angle_says_plain_number(tmp_path, model):
    errors, _ = run(tmp_path, model, "topic /pose.orientation.z > 1 rad")
    assert errors == [(31, "compares a plain number with an angle")]
    assert run(tmp_path, model, "topic /pose.orientation.z > 0.7") == ([], [])


def test_a_slice_past_the_end_also_warns_beside_errors(tmp_path, model):
    errors, warnings = run(tmp_path, model, "min(topic /odom.covariance[30:40]) > -1 and topic /pose.position.x > 1 s")
    assert [m for _, m in errors] == ["compares a length with a time"]
    assert [c for c, _ in warnings] == [9]
