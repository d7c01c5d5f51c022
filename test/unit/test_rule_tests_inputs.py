"""`rubass test` inputs as TESTING.md states them: header stamps in test time however they are
written, and quoted strings repeated in series."""
import pytest

from rubass.cli import main
from rubass.testing.series import SeriesError, expand

LIB = "actions:\n  warn: {plugin: log, level: warn}\n"
HEAD = 'import "lib.yaml";\naction primitive warn;\n'
SPEC = HEAD + """entity imu {
  rules:
    stale: stamp_age(topic /s) > 0.5 s;
}
stale: if (imu.stale) then { warn; }
"""


def run(capsys, *args):
    code = main(["test", *args])
    out, err = capsys.readouterr()
    return code, out, err


def test_quoted_strings_repeat_and_keep_an_x_inside_their_quotes():
    assert expand('"ab"x2') == ["ab", "ab"]
    assert expand("'a b'x3 0") == ["a b", "a b", "a b", 0.0]
    assert expand('"ax2"') == ["ax2"]
    assert expand('"a\\"x2"x2') == ['a"x2', 'a"x2']
    assert expand(['"ab"x2', 1]) == ["ab", "ab", 1.0]
    with pytest.raises(SeriesError, match="'x2y'"):
        expand('"ab"x2y')
    with pytest.raises(SeriesError):
        expand('"ab"+1x3')


def test_repeated_quoted_string_in_a_series_file(write, capsys):
    write("lib.yaml", LIB)
    write("robot.rbs", HEAD + 'entity e {\n  rules:\n    odd: topic /f.header.frame_id == "b";\n}\n'
          'odd: if (e.odd) then { warn; }\n')
    path = write("t.test.yaml", """spec: robot.rbs
tests:
  - name: frames
    duration: 1 s
    topics:
      /f:
        type: sensor_msgs/Imu
        rate: 10 Hz
        field: header.frame_id
        values: '"a"x2 "b"x3 "a"'
    expect:
      - {at: 0.2 s, start: odd}
      - {at: 0.5 s, release: odd}
""")
    code, out, err = run(capsys, path)
    assert code == 0, out + err


@pytest.mark.parametrize("message", ["{at: 1 s, header: {stamp: 0.95}}",
                                     "{at: 1 s, header.stamp: 0.95}",
                                     "{at: 1 s, header: {stamp: 0.95, frame_id: imu}}"])
def test_a_header_stamp_is_test_time_nested_or_dotted(write, capsys, message):
    write("lib.yaml", LIB)
    write("robot.rbs", SPEC)
    path = write("t.test.yaml", f"""spec: robot.rbs
tests:
  - name: stamp
    duration: 2 s
    topics:
      /s: {{type: sensor_msgs/Imu, messages: [{message}]}}
    expect:
      - {{at: 1.45 s, start: stale}}
""")
    code, out, err = run(capsys, path)
    assert code == 0, out + err


def test_a_zero_nested_stamp_stays_the_zero_stamp(write, capsys):
    write("lib.yaml", LIB)
    write("robot.rbs", SPEC)
    path = write("t.test.yaml", """spec: robot.rbs
tests:
  - name: zero
    duration: 2 s
    topics:
      /s: {type: sensor_msgs/Imu, messages: [{at: 1 s, header: {stamp: 0}}]}
    expect:
      - {never: stale}
""")
    code, out, err = run(capsys, path)
    assert code == 0, out + err


def test_a_series_of_header_stamps_is_test_time(write, capsys):
    write("lib.yaml", LIB)
    write("robot.rbs", SPEC)
    path = write("t.test.yaml", """spec: robot.rbs
tests:
  - name: lagging stamps
    duration: 1.5 s
    topics:
      /s:
        type: sensor_msgs/Imu
        rate: 10 Hz
        start: 1 s
        field: header.stamp
        values: "0.3"
    expect:
      - {at: 1 s, start: stale}
""")
    code, out, err = run(capsys, path)
    assert code == 0, out + err


@pytest.mark.parametrize("message", ["{at: 1 s, header: {stamp: -0.5}}", "{at: 1 s, header.stamp: -0.5}"])
def test_a_stamp_before_the_test_start_is_an_error_at_its_line(write, capsys, message):
    write("lib.yaml", LIB)
    write("robot.rbs", SPEC)
    path = write("t.test.yaml", f"""spec: robot.rbs
tests:
  - name: negative
    topics:
      /s:
        type: sensor_msgs/Imu
        messages:
          - {message}
""")
    code, out, err = run(capsys, path)
    assert code == 2 and "t.test.yaml:8: error:" in err and "before the test's start" in err, err
    assert "Traceback" not in out + err
