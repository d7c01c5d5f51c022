"""Re-sweep findings of the checker: a slice empty whatever the array's length ([100:90], [-1:-3]) and
`len()` of a path that goes on past its array (`len(topic /diag.status[*].values)` counted statuses)
read nothing for ever while `check` said ok; an array inside each element of the array a term runs
over is two arrays; a slice before the start is said to run past the start."""
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
  /m: t_msgs/Grid
  /odom: t_msgs/Odom
definitions:
  t_msgs/Grid: |
    t_msgs/Row[] rows
  t_msgs/Row: |
    float64[] v
    float64 w
  t_msgs/Odom: |
    float64[36] covariance
"""


def run(tmp_path, cond, model=False):
    """(errors, warnings) as (col, message) of `if (cond) then { warn; }` on line 3."""
    (tmp_path / "actions.yaml").write_text(LIB)
    text = HEAD + f"if ({cond}) then {{ warn; }}\n"
    (tmp_path / "s.rbs").write_text(text)
    m = None
    if model:
        m, diags = parse_model(Source("robot.yaml", MODEL))
        assert m is not None, diags
    try:
        checked = check_source(Source(str(tmp_path / "s.rbs"), text), model=m)
    except SpecError as exc:
        return [(d.span.col, d.message) for d in exc.diagnostics], [(d.span.col, d.message) for d in exc.warnings]
    return [], [(d.span.col, d.message) for d in checked.warnings]


@pytest.mark.parametrize("term,better", [("[100:90]", "[90:100]"), ("[-1:-3]", "[-3:-1]"), ("[5:5]", None)])
@pytest.mark.parametrize("model", [False, True])
def test_a_slice_empty_whatever_the_length_is_an_error(tmp_path, term, better, model):
    for cond in (f"any(topic /scan.ranges{term} < 1 m)", f"min(topic /odom.covariance{term}) > -1"):
        errors, _ = run(tmp_path, cond.replace("/scan.ranges", "/odom.covariance") if model else cond, model)
        assert len(errors) == 1 and f"a slice '{term}' selects no element whatever the array's length" in errors[0][1], \
            errors
        assert (f"did you mean '{better}'" in errors[0][1]) if better else "did you mean" not in errors[0][1]


@pytest.mark.parametrize("term", ["[90:100]", "[-3:-1]", "[-10:]", "[:-1]", "[*]", "[-3:2]", "[2:-3]"])
def test_slices_that_may_select_something_are_accepted(tmp_path, term):
    assert run(tmp_path, f"min(topic /scan.ranges{term}) < 1 m")[0] == []


def test_len_of_a_path_going_on_past_its_array_is_an_error_whatever_the_model(tmp_path):
    errors, _ = run(tmp_path, "len(topic /diag.status[*].values) == 2")
    assert errors == [(9, "len() counts the elements of an array: 'topic /diag.status[*].values' would count those "
                          "of 'topic /diag.status[*]' whatever 'values' is; write len(topic /diag.status[*]), or "
                          "index one element: len(topic /diag.status[0].values)")]
    assert run(tmp_path, "len(topic /diag.status) == 2 and len(topic /diag.status[0].values) == 1")[0] == []


def test_an_array_in_each_element_is_a_second_array(tmp_path):
    errors, _ = run(tmp_path, "max(topic /m.rows[*].v) > 1", model=True)
    assert len(errors) == 1 and "a field path runs over one array only" in errors[0][1], errors
    assert "'v' is an array in each element of 'topic /m.rows[*]'" in errors[0][1]
    assert "topic /m.rows[0].v" in errors[0][1]
    assert run(tmp_path, "max(topic /m.rows[*].w) > 1 and max(topic /m.rows[0].v) > 1", model=True)[0] == []


def test_a_slice_before_the_start_runs_past_the_start(tmp_path):
    _, warnings = run(tmp_path, "min(topic /odom.covariance[-40:2]) > -1", model=True)
    assert any("runs past the start" in w for _, w in warnings), warnings
    _, warnings = run(tmp_path, "min(topic /odom.covariance[30:40]) > -1", model=True)
    assert any("runs past the end" in w for _, w in warnings), warnings


def test_a_number_too_small_for_a_float_is_an_error_not_a_silent_zero(tmp_path):
    errors, _ = run(tmp_path, "topic /a.data > 1e-999 m")
    assert errors == [(21, "the number '1e-999' is too small: it would be read as 0 (the smallest is about 5e-324)")]
    assert run(tmp_path, "topic /a.data > 0.0 m or topic /a.data > 0e5 m or topic /a.data > 1e-300 m")[0] == []
