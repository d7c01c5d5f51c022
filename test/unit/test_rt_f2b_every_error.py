"""`rubass test`: every error a file's reading can find is said in one run, in line order, past a missing
spec, a bad field, a type that is not installed or a bad rate (F2b items 1 and 2); a file not run says so
on stdout instead of `0 passed, 0 failed`."""
import pytest

from rubass.cli import main

LIB = """actions:
  stop: {plugin: log, level: warn}
"""
SPEC = """import "lib.yaml";
action primitive stop;
entity e {
  rules:
    fast: topic /odom.twist.twist.linear.x > 0.5 m/s;
    far: topic /scan.range_max < 0.3 m;
}
if (e.fast or e.far) then { stop; }
"""
TESTS = """  - name: a
    topics:
      /odom:
        type: nav_msgs/Odometry
        rate: 10 Hz
        field: FIELD
        values: "0x5 abc 1x10"
    expect:
      - {at: -1 s, start: behaviour 1}
      - {at: 1 s, strat: stop}
  - name: b
    topics:
      /scan:
        type: TYPE
        rate: 0 Hz
        field: range_max
        values: "1x10"
    expect:
      - {never: stpo}
"""


def run(capsys, *args):
    code = main(["test", *args])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def files(write):
    write("lib.yaml", LIB)
    write("t.rbs", SPEC)

    def make(head="spec: t.rbs\n", field="twist.twist.linear.x", type_="sensor_msgs/LaserScan"):
        return write("m.test.yaml", head + "tests:\n" + TESTS.replace("FIELD", field).replace("TYPE", type_))

    return make


def errors(err):
    return [line.split(": error: ")[0].rsplit(":", 1)[1] + ": " + line.split(": error: ", 1)[1]
            for line in err.splitlines() if ": error: " in line]


def test_a_misspelt_spec_key_hides_nothing_the_spec_is_not_needed_for(files, capsys):
    path = files(head="spce: t.rbs\n")
    code, out, err = run(capsys, path)
    said = errors(err)
    assert code == 2
    assert said == [
        "1: unknown key 'spce' in a test file; did you mean 'spec'? (keys: spec, actions, model, tests)",
        "9: values of twist.twist.linear.x: 'abc' is not a value (a number, nan, inf, true, false or a quoted string)",
        "11: at must not be negative",
        "12: unknown key 'strat' in an expectation; did you mean 'start'? (keys: at, start, release, never, "
        "active, from, to, tolerance)",
        "17: rate must be more than 0 Hz"], err  # 'stpo' (21) needs the spec to be found out
    assert out.strip() == f"not run: {len(said)} errors in {path}\n0 passed, 0 failed"  # not a clean "0 passed"


def test_a_negative_at_beside_a_misspelt_key_of_the_same_line_is_said_too(write, capsys):
    path = write("n.test.yaml", "spce: t.rbs\ntests:\n  - name: a\n    expect:\n      - {at: -1 s, strat: stop}\n")
    code, out, err = run(capsys, path)
    assert code == 2
    assert errors(err) == [
        "1: unknown key 'spce' in a test file; did you mean 'spec'? (keys: spec, actions, model, tests)",
        "5: unknown key 'strat' in an expectation; did you mean 'start'? (keys: at, start, release, never, active, "
        "from, to, tolerance)",
        "5: at must not be negative"], err
    assert out.strip() == f"not run: 3 errors in {path}\n0 passed, 0 failed"


def test_a_missing_spec_is_said_when_nothing_else_is_at_its_line(write, capsys):
    path = write("n.test.yaml", "tests:\n  - name: a\n    expect:\n      - {at: -2 s, never: x}\n")
    code, out, err = run(capsys, path)
    assert code == 2 and errors(err) == ["1: a test file needs 'spec'", "4: at must not be negative"], err


def test_a_bad_field_hides_neither_its_values_nor_what_follows(files, capsys):
    path = files(field="twist.twist.linear.y.z", type_="sensor_msgs/LaserScans")
    code, out, err = run(capsys, path)
    assert code == 2
    assert errors(err) == [
        "8: /odom (nav_msgs/Odometry): 'twist.twist.linear.y' is a float64, not a message: it has no field 'z'",
        "9: values of twist.twist.linear.y.z: 'abc' is not a value (a number, nan, inf, true, false or a quoted "
        "string)",
        "11: at must not be negative",
        "12: unknown key 'strat' in an expectation; did you mean 'start'? (keys: at, start, release, never, active, "
        "from, to, tolerance)",
        "16: message type sensor_msgs/LaserScans is not installed here (is its Debian package installed?)",
        "17: rate must be more than 0 Hz",  # was hidden by the type
        "21: 'stpo' is neither a behaviour's name nor a declared action; did you mean 'stop'?"], err
    assert out.strip() == f"not run: 7 errors in {path}\n0 passed, 0 failed"


def test_without_its_type_a_series_values_are_still_read(write, capsys):
    write("lib.yaml", LIB)
    write("t.rbs", SPEC)
    path = write("u.test.yaml", """spec: t.rbs
tests:
  - name: a
    topics:
      /scan:
        type: sensor_msgs/LaserScans
        rate: 10 Hz
        field: range_max
        values: "1x5 2 Hz 3qq"
""")
    code, out, err = run(capsys, path)
    said = errors(err)
    assert code == 2 and said[0].startswith("6: message type sensor_msgs/LaserScans is not installed"), said
    assert len(said) == 2 and said[1].startswith("9: values of range_max: "), said


def test_a_file_not_run_beside_one_that_ran(files, write, capsys):
    bad = files(head="spce: t.rbs\n")
    good = write("g.test.yaml", """spec: t.rbs
tests:
  - name: g
    topics:
      /odom: {type: nav_msgs/Odometry, rate: 10 Hz, field: twist.twist.linear.x, values: "0x5"}
    expect:
      - {never: 1}
""")
    code, out, err = run(capsys, good, bad)
    n = len(errors(err))
    assert code == 2 and out.rstrip().splitlines()[-2:] == [f"not run: {n} errors in {bad}", "1 passed, 0 failed"], out


def test_a_bad_time_and_an_unknown_name_of_one_expectation_are_both_said(files, write, capsys):
    files()
    path = write("n.test.yaml", "spec: t.rbs\ntests:\n  - name: a\n    expect:\n      - {at: -1 s, start: stpo}\n")
    code, out, err = run(capsys, path)
    assert code == 2 and errors(err) == [
        "5: at must not be negative",
        "5: 'stpo' is neither a behaviour's name nor a declared action; did you mean 'stop'?"], err
