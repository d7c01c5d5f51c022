"""`rubass test` and `rubass report`: the defects an acceptance tester reproduced, each pinned down."""
import re
import xml.etree.ElementTree as ET

import pytest

from rubass.cli import main
from rubass.report.bench import from_readme
from rubass.testing.messages import convert
from rubass.testing.runner import _intervals

LIB = """actions:
  stop: {plugin: log, level: warn}
  warn: {plugin: log, level: warn}
"""
SPEC = """import "lib.yaml";
action primitive stop, warn;
entity base: controller {
  rules:
    @id("SR-1") @hazard("H1")
    too_fast: topic /odom.twist.twist.linear.x > 0.5 m/s for 1 s;
    @id("SR-2") @hazard("H2")
    fast: topic /odom.twist.twist.linear.x > 0.5 m/s;
    @id("SR-3") @hazard("H3")
    turning: topic /cmd_vel.angular.z > 1 rad/s;
}
overspeed: if (base.too_fast) then { stop; }
speeding: if (base.fast) then { warn; }
spin: if (base.turning) then { warn; }
"""
ODOM = """      /odom:
        type: nav_msgs/Odometry
        rate: 10 Hz
        field: twist.twist.linear.x
        values: "{values}"
"""


@pytest.fixture
def files(write):
    write("lib.yaml", LIB)
    write("robot.rbs", SPEC)

    def make(tests, name="robot.test.yaml"):
        return write(name, "spec: robot.rbs\ntests:\n" + tests)

    return make


def run(capsys, *args):
    code = main(["test", *args])
    out, err = capsys.readouterr()
    return code, out, err


def line_of(path, text, nth=0):
    lines = [k + 1 for k, line in enumerate(open(path, encoding="utf-8").read().splitlines()) if text in line]
    return lines[nth]


# 1 -- an `active` expectation past the test's end -------------------------------------------------------


def test_an_interval_still_open_at_the_end_ends_there():
    assert _intervals([("start", 2.0)], 2.5) == [(2.0, 2.5, True)]
    assert _intervals([("start", 1.0), ("release", 2.0), ("start", 2.2)], 3.0) == [(1.0, 2.0, False),
                                                                                   (2.2, 3.0, True)]


def test_active_beyond_the_duration_is_an_error_at_its_line(files, capsys):
    path = files("""  - name: active past the end
    duration: 2.5 s
    topics:
""" + ODOM.format(values="0x10 0.6x20 0x10") + """    expect:
      - {active: overspeed, from: 2.5 s, to: 60 s}
""")
    code, out, err = run(capsys, path)
    assert code == 2, out + err
    assert f"{path}:{line_of(path, 'active: overspeed')}: error: active until 60 s is after the test's end " \
           f"(duration 2.5 s)" in err
    assert "0 passed, 0 failed" in out


def test_a_start_after_the_duration_is_an_error(files, capsys):
    path = files("""  - name: start past the end
    duration: 2 s
    topics:
""" + ODOM.format(values="0x10 0.6x20 0x10") + """    expect:
      - {at: 3 s, release: overspeed}
""")
    code, _, err = run(capsys, path)
    assert code == 2 and f"{path}:{line_of(path, 'release: overspeed')}: error: release at 3 s is after" in err


def test_active_up_to_the_end_passes_and_a_failure_shows_the_open_span(files, capsys):
    path = files("""  - name: active until the end
    duration: 2.5 s
    topics:
""" + ODOM.format(values="0x10 0.6x20 0x10") + """    expect:
      - {active: overspeed, from: 2.0 s, to: 2.5 s}
  - name: active too early
    duration: 2.5 s
    topics:
""" + ODOM.format(values="0x10 0.6x20 0x10") + """    expect:
      - {active: overspeed, from: 1.5 s, to: 2.5 s}
""")
    code, out, err = run(capsys, path)
    assert code == 1, out + err
    assert "PASS  active until the end" in out and "FAIL  active too early" in out
    assert "but active: [2.000, 2.500] (still active at the test's end)" in out


# 3 -- `_` in one of several fields ---------------------------------------------------------------------------


def test_a_gap_in_one_field_only_is_an_error_at_its_line(files, capsys):
    path = files("""  - name: mixed
    topics:
      /cmd_vel:
        type: geometry_msgs/Twist
        rate: 10 Hz
        fields:
          angular.z: "2 2 2"
          linear.x: "2 _ 2"
""")
    code, out, err = run(capsys, path)
    assert code == 2, out + err
    assert f"{path}:{line_of(path, 'linear.x:')}: error: step 2 of /cmd_vel (at 0.1 s) is _ (no message) in " \
           f"linear.x but a value in angular.z" in err


def test_a_gap_in_every_field_is_silence(files, capsys):
    path = files("""  - name: all gaps
    duration: 1 s
    topics:
      /cmd_vel: {type: geometry_msgs/Twist, rate: 10 Hz, fields: {linear.x: "0 _ 0", angular.z: "2 _ 2"}}
    expect:
      - {at: 0 s, start: spin}
""")
    code, out, err = run(capsys, path)
    assert code == 0, out + err


# 4 -- units of series values against the field ----------------------------------------------------------------


@pytest.mark.parametrize("values, said", [
    ("0sx10 600msx20 0x10", "'0s' is a time (s), but twist.twist.linear.x is a speed (units: m/s, cm/s, km/h)"),
    ("0x10 60%x20 0x10", "'60%' is a share (%), but twist.twist.linear.x is a speed"),
    ("0x10 600mm/sx20 0x10", "'600mm/s': 'mm/s' is not a unit rubass knows (units of a speed: m/s, cm/s, km/h)"),
])
def test_a_value_of_another_dimension_is_an_error(files, capsys, values, said):
    path = files("  - name: units\n    topics:\n" + ODOM.format(values=values))
    code, out, err = run(capsys, path)
    assert code == 2, out + err
    assert f"{path}:{line_of(path, 'values:')}: error: values of twist.twist.linear.x: {said}" in err


def test_a_value_with_a_unit_of_the_field_is_converted(files, capsys):
    path = files("  - name: cm/s\n    topics:\n" + ODOM.format(values="0x10 60cm/sx20 0x10") + """    expect:
      - {at: 2 s, start: overspeed}
      - {at: 3 s, release: overspeed}
  - name: km/h, below the limit
    topics:
""" + ODOM.format(values="0x10 1.5km/hx20 0x10") + """    expect:
      - {never: overspeed}
""")
    code, out, err = run(capsys, path)
    assert code == 0, out + err


# 6 -- the later entry wins per field, series or message ------------------------------------------------------


@pytest.mark.parametrize("first, later, starts", [
    ("messages", "series", False),  # the series (0) written after the message (0.6) wins at 1 s
    ("series", "messages", True),
])
def test_the_later_entry_in_the_file_wins(files, capsys, first, later, starts):
    parts = {"series": "        field: twist.twist.linear.x\n        values: \"0x30\"\n",
             "messages": "        messages:\n          - {at: 1 s, twist.twist.linear.x: 0.6}\n"}
    path = files("""  - name: order
    duration: 3 s
    topics:
      /odom:
        type: nav_msgs/Odometry
        rate: 10 Hz
""" + parts[first] + parts[later] + """    expect:
      - {never: speeding}
""")
    code, out, err = run(capsys, path)
    assert code == (1 if starts else 0), out + err


# 7 -- nan and inf in explicit messages ---------------------------------------------------------------------------


def test_nan_and_inf_strings_in_explicit_messages():
    values = convert("float32[]", ["nan", "inf", "-inf", "+inf", "NaN"], "'ranges'")
    assert values[0] != values[0] and values[1:4] == [float("inf"), float("-inf"), float("inf")]
    assert values[4] != values[4]
    with pytest.raises(ValueError, match="'nope' is not a number"):
        convert("float64", "nope", "'x'")


def test_an_explicit_message_with_nan_runs(files, capsys):
    path = files("""  - name: nan range
    topics:
      /scan:
        type: sensor_msgs/LaserScan
        messages:
          - {at: 1 s, ranges: [nan, 0.3, inf], range_min: 0.1, range_max: 10.0}
""")
    code, out, err = run(capsys, path)
    assert code == 0 and "is not a number" not in err, out + err


# 8 -- errors and warnings at the right line ------------------------------------------------------------------------


def test_a_wrong_field_is_reported_at_the_field_line(files, capsys):
    path = files("""  - name: wrong field
    topics:
      /odom:
        type: nav_msgs/Odometry
        rate: 10 Hz
        field: twist.linear.x
        values: "0x10"
""")
    code, _, err = run(capsys, path)
    assert code == 2
    assert f"{path}:{line_of(path, 'field: twist.linear.x')}: error: /odom (nav_msgs/Odometry): 'twist' " \
           f"(geometry_msgs/TwistWithCovariance) has no field 'linear'; did you mean 'twist.twist.linear'?" in err


def test_an_unknown_key_is_reported_at_its_own_line(files, capsys):
    path = files("""  - name: typo
    topics:
""" + ODOM.format(values="0x10") + """    expects:
      - {never: overspeed}
""")
    code, _, err = run(capsys, path)
    assert code == 2 and f"{path}:{line_of(path, 'expects:')}: error: unknown key 'expects'" in err


def test_a_mistyped_covers_value_is_warned_at_its_line(files, capsys):
    path = files("""  - name: typo in covers
    covers:
      - SR-1
      - SR-9
    topics:
""" + ODOM.format(values="0x10"))
    code, _, err = run(capsys, path)
    assert code == 0
    assert f"{path}:{line_of(path, '- SR-9')}: warning: test 'typo in covers' covers 'SR-9'" in err


# 9, 10 -- a failed start names its line; JUnit that parses, with a useful message ---------------------------------


FAILING = """  - name: "bad\\x01name"
    topics:
""" + ODOM.format(values="0x10 0.6x20 0x10") + """    expect:
      - {at: 2.5 s, start: overspeed}
      - {at: 3 s, release: overspeed}
"""


def test_a_failed_start_names_its_lines_and_junit_parses(files, capsys, tmp_path):
    path = files(FAILING)
    xml = str(tmp_path / "out.xml")
    code, out, err = run(capsys, path, "--junit", xml)
    assert code == 1, out + err
    lines = f"lines {line_of(path, 'start: overspeed')}, {line_of(path, 'release: overspeed')}"
    assert f"overspeed ({lines}):\n      expected: start at 2.500 s, release at 3.000 s" in out
    root = ET.parse(xml).getroot()  # a control character in a name does not break the XML
    case = root.find("testsuite/testcase")
    assert case.get("name") == "bad\\x01name"
    message = case.find("failure").get("message")
    assert message == f"overspeed ({lines}): expected: start at 2.500 s, release at 3.000 s (each ± 1 ms); " \
                      f"actual: start at 2.000 s, release at 3.000 s"  # the tolerance is said (later fix)


def test_junit_that_cannot_be_written_still_prints_the_count(files, tmp_path, capsys):
    path = files(FAILING)
    blocker = tmp_path / "blocker"
    blocker.write_text("a file where the folder would be")  # missing folders are made now; this one cannot be
    code, out, err = run(capsys, path, "--junit", str(blocker / "x.xml"))
    assert code == 2
    assert out.rstrip().splitlines()[-1] == "0 passed, 1 failed"
    assert f"rubass test: error: cannot write {blocker}/x.xml" in err


# 11 -- covers entries that are no names -------------------------------------------------------------------------


def test_a_covers_entry_that_is_no_name_is_an_error(files, capsys):
    path = files("""  - name: null in covers
    covers: [1, null]
    topics:
""" + ODOM.format(values="0x10"))
    code, _, err = run(capsys, path)
    assert code == 2
    assert f"{path}:{line_of(path, 'covers:')}: error: covers lists @id and @hazard values of the spec: an empty " \
           f"entry is not one" in err
    assert "None" not in err


# 2, 11 -- the report: one meaning of covered ------------------------------------------------------------------


REPORT_TESTS = """spec: robot.rbs
tests:
  - name: overspeed stops
    covers: [SR-1]
    topics:
      /odom: {type: nav_msgs/Odometry, rate: 10 Hz, field: twist.twist.linear.x, values: "0x10 0.6x20 0x10"}
    expect:
      - {at: 2 s, start: overspeed}
      - {at: 3 s, release: overspeed}
"""


def test_the_matrix_and_the_coverage_agree_on_covered(write, tmp_path, capsys):
    write("lib.yaml", LIB)
    spec = write("robot.rbs", SPEC)
    tests = write("robot.test.yaml", REPORT_TESTS)
    out = str(tmp_path / "r.html")
    assert main(["report", spec, "--tests", tests, "-o", out]) == 0
    printed = capsys.readouterr().out
    assert "1 test passed, 0 failed, 3 gaps in the matrix" in printed
    html = open(out, encoding="utf-8").read()
    # the test made base.fast (SR-2, H2) true but names neither: it covers nothing of that row
    h2 = re.search(r"<tr><td><b>H2</b>.*?</tr>", html, re.S).group(0)
    assert "overspeed stops" not in h2 and "covered" not in h2
    assert "no test covers SR-2" in h2 and "no test covers hazard H2" in h2
    # SR-1 is named, H1 is not: the coverage lists H1, so the row does too
    h1 = re.search(r"<tr><td><b>H1</b>.*?</tr>", html, re.S).group(0)
    assert "overspeed stops" in h1 and "no test covers hazard H1" in h1
    coverage = html.split("<h3>Coverage over all tests</h3>", 1)[1]
    assert "SR-2, SR-3" in coverage and "H1, H2, H3" in coverage


def test_a_row_is_covered_when_its_rule_and_hazard_are_named(write, tmp_path, capsys):
    write("lib.yaml", LIB)
    spec = write("robot.rbs", SPEC)
    tests = write("robot.test.yaml", REPORT_TESTS.replace("covers: [SR-1]", "covers: [SR-1, H1]"))
    out = str(tmp_path / "r.html")
    assert main(["report", spec, "--tests", tests, "-o", out]) == 0
    html = open(out, encoding="utf-8").read()
    h1 = re.search(r"<tr><td><b>H1</b>.*?</tr>", html, re.S).group(0)
    assert "<td class='ok'>covered</td>" in h1


# 5 -- the benchmark's date and what its figures are -------------------------------------------------------------


README = """# Benchmarks

## engine.py

Figures of 2026-11-23 (idle).

# Benchmarks against the physical limit (ROS)

Figures of 2026-11-21, same machine.

## reaction.py — rubass's reaction

| rate | load | raw | rubass p50 / p99 / max | ratio | missed |
|---|---|---|---|---|---|
| 100 Hz | none | 0.1 / 0.2 ms | 0.358 / 1.979 / 4.1 ms | 1.39 | 0 |
| 1 kHz | none | 0.1 / 0.2 ms | 0.226 / 2.393 / 5.4 ms | 1.92 | 0 |

## later.py

Figures of 2026-11-25.
"""


def test_the_readme_figures_take_their_own_sections_date(tmp_path):
    path = tmp_path / "README.md"
    path.write_text(README, encoding="utf-8")
    r = from_readme(str(path))
    assert r is not None and r.source.endswith("figures of 2026-11-21)")
    assert r.figures() == "largest p50 0.358 ms, largest p99 2.393 ms and worst 5.4 ms over 2 cases"
    assert r.p99_label() == "largest p99 of 2 cases"
    one = README.replace("| 1 kHz | none | 0.1 / 0.2 ms | 0.226 / 2.393 / 5.4 ms | 1.92 | 0 |\n", "")
    path.write_text(one.replace("Figures of 2026-11-21, same machine.", "No date here."), encoding="utf-8")
    r = from_readme(str(path))
    assert r.figures() == "p50 0.358 ms, p99 1.979 ms, worst 4.1 ms" and "figures of" not in r.source


def test_a_named_rule_never_true_is_a_gap_as_in_the_coverage(write, tmp_path, capsys):
    write("lib.yaml", LIB)
    spec = write("robot.rbs", SPEC)
    tests = write("robot.test.yaml", REPORT_TESTS.replace("covers: [SR-1]", "covers: [SR-1, H1, SR-3, H3]"))
    out = str(tmp_path / "r.html")
    assert main(["report", spec, "--tests", tests, "-o", out]) == 0
    html = open(out, encoding="utf-8").read()
    h3 = re.search(r"<tr><td><b>H3</b>.*?</tr>", html, re.S).group(0)  # named, but /cmd_vel never came
    assert "overspeed stops" in h3 and "never true in any test" in h3 and "covered" not in h3
    coverage = html.split("<h3>Coverage over all tests</h3>", 1)[1]
    assert re.search(r"rules never true</th><td class='gap'>[^<]*base.turning", coverage)


def test_a_word_that_is_no_number_is_no_value():
    from rubass.testing.series import SeriesError, expand

    for word in ("1,5", "0.5.5", "abc"):
        with pytest.raises(SeriesError, match=f"'{re.escape(word)}' is not a value"):
            expand(word)


def test_two_spellings_of_one_topic_are_one_topic(files, capsys):
    path = files("""  - name: two series of one topic
    duration: 3 s
    topics:
      /cmd_vel: {type: geometry_msgs/Twist, rate: 10 Hz, field: linear.x, values: "0x30"}
      cmd_vel: {type: geometry_msgs/Twist, rate: 10 Hz, field: angular.z, values: "0x10 2x20"}
    expect:
      - {at: 1 s, start: spin}
""")
    code, out, err = run(capsys, path)
    assert code == 0, out + err
    path = files("""  - name: two types
    topics:
      /cmd_vel: {type: geometry_msgs/Twist, rate: 10 Hz, field: linear.x, values: "0x30"}
      cmd_vel: {type: nav_msgs/Odometry, rate: 10 Hz, field: twist.twist.linear.x, values: "0x30"}
""")
    code, out, err = run(capsys, path)
    assert code == 2 and f"{path}:{line_of(path, 'cmd_vel: {type: nav')}: error: topic /cmd_vel is " \
                         f"geometry_msgs/Twist at line {line_of(path, '/cmd_vel:')}" in err
