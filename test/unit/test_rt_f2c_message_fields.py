"""`rubass test`: the fields and values of explicit `messages:` are checked when the file is read, so that
their errors are said in one run with every other error, in line order, even past a misspelt `spec:`;
a `covers` value in the wrong case is suggested in the spec's case (F2c)."""
import pytest

from rubass.cli import main
from rubass.testing.format import read_test_file

SPEC = """action primitive stop, slow_down;
entity base {
  rules:
    @id("SR-1") @hazard("H1")
    too_fast: topic /odom.twist.twist.linear.x > 0.5 m/s;
    @id("SR-2") @hazard("H2")
    obstacle: min(topic /scan.ranges) < 0.4 m;
}
overspeed: if (base.too_fast for 1 s) then { slow_down; }
near: if (base.obstacle) then { stop; }
"""
LIB = """actions:
  stop: {plugin: log, level: warn}
  slow_down: {plugin: log, level: warn}
"""
TEST = """spec: SPEC
actions: [lib.yaml]
tests:
  - name: typos in messages
    covers: [SR-2]
    topics:
      /scan:
        type: sensor_msgs/LaserScan
        messages:
          - {at: 1 s, range: [1.0, 0.3], range_min: 0.1, range_max: 10.0}
          - {at: 1.5 s, ranges: [1.0, 0.3], header: {stmp: 1.2}}
          - {at: 2 s, ranges: [1.0, 0.3], header.frame: "x"}
      /odom:
        type: nav_msgs/Odometry
        rate: 10 Hz
        fields: {twist.twist.linear.x: "0x5", twist.twist.angullar.z: "0x5"}
      /cmd_vel:
        type: geometry_msgs/Twist
        messages:
          - {at: 1 s, linear: {x: 0.2, q: 3}}
          - {at: 1 s, linear.x: "fast"}
          - {at: 2 s, angular.z: 1.5, lineer.x: 2}
          - at: 3 s
            angular.z: 1.5
            angular.w: 2
            linear.x: [1]
    expect:
      - {at: 1 s, start: near}
"""
# line: what is wrong there
WANTED = {
    10: "no field 'range'; did you mean 'ranges'?",
    11: "no field 'stmp'; did you mean 'stamp'?",
    12: "no field 'frame'; did you mean 'frame_id'?",
    16: "no field 'angullar'; did you mean 'angular'?",
    20: "'linear' (geometry_msgs/Vector3) has no field 'q'",
    21: "linear.x is a float64: 'fast' is not a number",
    22: "no field 'lineer'; did you mean 'linear'?",
    25: "'angular' (geometry_msgs/Vector3) has no field 'w'",
    26: "linear.x is a float64: [1] is not a number",
}


@pytest.fixture
def run(write, capsys):
    def _run(spec="robot.rbs", test=TEST):
        write("robot.rbs", SPEC)
        write("lib.yaml", LIB)
        path = write("f.test.yaml", test.replace("SPEC", spec))
        code = main(["test", str(path)])
        out, err = capsys.readouterr()
        errors = [(int(line.split(": error: ")[0].rsplit(":", 1)[1]), line.split(": error: ", 1)[1])
                  for line in err.splitlines() if line.startswith(str(path) + ":") and ": error: " in line]
        return code, out, err, errors

    return _run


def _check(errors, spec_error=False):
    lines = [n for n, _ in errors]
    assert lines == sorted(lines)  # line order
    assert lines == ([1] if spec_error else []) + sorted(WANTED)  # every one, each once
    for n, text in errors:
        if n in WANTED:
            assert WANTED[n] in text, (n, text)


def test_every_message_field_error_is_said_with_a_series_error_in_line_order(run):
    code, out, err, errors = run()
    assert code == 2
    _check(errors)
    assert "not run: 9 errors" in out


def test_message_field_errors_are_said_past_a_misspelt_spec(run):
    code, _, err, errors = run(spec="robott.rbs")
    assert code == 2
    _check(errors, spec_error=True)
    assert "robott.rbs" in errors[0][1]


def test_a_bad_at_and_a_bad_field_of_one_message_are_both_said(run):
    test = TEST.replace("{at: 1 s, linear.x: \"fast\"}", "{at: -1 s, linear.x: \"fast\"}")
    _, _, _, errors = run(test=test)
    at21 = [text for n, text in errors if n == 21]
    assert len(at21) == 2 and any("negative" in t for t in at21) and any("'fast'" in t for t in at21)


def test_a_negative_header_stamp_is_an_error_when_the_file_is_read(write):
    write("robot.rbs", SPEC)
    path = write("s.test.yaml", """spec: robot.rbs
tests:
  - name: s
    topics:
      /scan:
        type: sensor_msgs/LaserScan
        messages:
          - {at: 1 s, ranges: [0.3], header.stamp: -2}
          - {at: 2 s, ranges: [0.3], header: {stamp: -1}}
          - {at: 3 s, ranges: [0.3], header: {stamp: 2.5}}
""")
    tf = read_test_file(str(path))
    assert [(e.line, "before the test's start" in e.message) for e in tf.errors] == [(8, True), (9, True)]


def test_an_integer_out_of_range_is_an_error_when_the_file_is_read(write):
    write("robot.rbs", SPEC)
    path = write("i.test.yaml", """spec: robot.rbs
tests:
  - name: i
    topics:
      /scan:
        type: sensor_msgs/LaserScan
        messages:
          - {at: 1 s, ranges: [0.3], header.seq: 99999999999}
""")
    tf = read_test_file(str(path))
    assert [e.line for e in tf.errors] == [8]
    assert "/scan (sensor_msgs/LaserScan): header.seq is a uint32: 99999999999 is out of range 0 to 4294967295" \
        in tf.errors[0].message  # the field, its type, the value and the range (a later fix's wording)


def test_good_messages_still_run_and_pass(run):
    test = """spec: SPEC
actions: [lib.yaml]
tests:
  - name: close
    topics:
      /scan:
        type: sensor_msgs/LaserScan
        messages:
          - {at: 1 s, ranges: [1.0, 0.3], header: {stamp: 1.0, frame_id: laser}}
          - at: 2 s
            ranges: [1.0]
            header.stamp: 2.0
    expect:
      - {at: 1 s, start: near}
      - {at: 2 s, release: near}
"""
    code, out, err, errors = run(test=test)
    assert (code, errors) == (0, []), err
    assert "1 passed, 0 failed" in out


def test_covers_in_the_wrong_case_is_suggested_in_the_spec_case(run):
    test = TEST.replace("covers: [SR-2]", "covers: [h1, sr-1, Sr-2x]")
    _, _, err, _ = run(test=test)
    warnings = [line for line in err.splitlines() if "warning:" in line]
    assert any("'h1'" in w and "did you mean 'H1'?" in w for w in warnings), warnings
    assert any("'sr-1'" in w and "did you mean 'SR-1'?" in w for w in warnings), warnings
    assert any("'Sr-2x'" in w and "did you mean 'SR-2'?" in w for w in warnings), warnings
