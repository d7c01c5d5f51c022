"""`rubass test`: the TESTING.md contract, from files written to a temporary folder."""
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest

from rubass.cli import main
from rubass.testing.series import GAP, SeriesError, expand

from conftest import ROOT

LIB = """actions:
  stop: {plugin: log, level: warn}
  warn: {plugin: log, level: warn}
"""

SPEC = """import "lib.yaml";
action primitive stop, warn;
entity base: controller {
  rules:
    too_fast: topic /odom.twist.twist.linear.x > 0.5 m/s for 1 s;
    close: topic /scan.range_min > 0.5 m;
    hot: cpu(node controller) > 90 %;
    silent: age(topic /cmd_vel) > 0.5 s;
}
overspeed: if (base.too_fast) then { stop; }
obstacle: if (base.close) then { stop; warn; }
if (base.hot) then { warn; }
if (base.silent) then { warn; }
"""

ODOM = """      /odom:
        type: nav_msgs/Odometry
        rate: 10 Hz
        field: twist.twist.linear.x
        values: "0x10 0.6x20 0x10"
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


def test_series_words():
    assert expand("0x2 1+0.5x3 1-0.1x2 _ _x2 nan true 'a b' 20%") [:7] == [0.0, 0.0, 1.0, 1.5, 2.0, 1.0, 0.9]
    steps = expand("_ _x2 nan true 'a b' 20% -inf")
    assert steps[:3] == [GAP] * 3 and steps[3] != steps[3] and steps[4:] == [True, "a b", 0.2, float("-inf")]
    assert expand("0+0.1x4")[3] == 0.3  # what the author meant, not 0.30000000000000004
    with pytest.raises(SeriesError):
        expand("0x3 abc")


def test_passing_file_prints_each_test_and_the_count(files, capsys):
    path = files("""  - name: overspeed stops after one second
    covers: [SR-1]
    topics:
""" + ODOM + """    expect:
      - {at: 2 s, start: overspeed}
      - {at: 3 s, release: overspeed}
      - {active: stop, from: 2.1 s, to: 2.9 s}
      - {never: obstacle}
""")
    code, out, err = run(capsys, path)
    assert code == 0, out + err
    assert "PASS  overspeed stops after one second" in out
    assert out.strip().splitlines()[-1] == "1 passed, 0 failed"


def test_failure_shows_expected_and_actual_and_exits_1(files, capsys):
    path = files("""  - name: wrong time
    topics:
""" + ODOM + """    expect:
      - {at: 2.5 s, start: overspeed}
      - {at: 3 s, release: overspeed}
""")
    code, out, _ = run(capsys, path)
    assert code == 1
    assert "FAIL  wrong time" in out
    assert "expected: start at 2.500 s, release at 3.000 s" in out
    assert "actual:   start at 2.000 s, release at 3.000 s" in out
    assert out.strip().splitlines()[-1] == "0 passed, 1 failed"


def test_tolerance_default_1ms_and_per_test(files, capsys):
    tmpl = """  - name: t
    {tol}
    topics:
""" + ODOM + """    expect:
      - {{at: {at}, start: overspeed}}
      - {{at: 3 s, release: overspeed}}
"""
    assert run(capsys, files(tmpl.format(tol="", at="2.0009 s")))[0] == 0
    assert run(capsys, files(tmpl.format(tol="", at="2.002 s")))[0] == 1
    assert run(capsys, files(tmpl.format(tol="tolerance: 5 ms", at="2.004 s")))[0] == 0


def test_every_event_of_a_mentioned_name_must_be_listed(files, capsys):
    # a release that is not listed fails the test; an unmentioned behaviour is free
    path = files("""  - name: t
    topics:
""" + ODOM + """    expect:
      - {at: 2 s, start: overspeed}
""")
    code, out, _ = run(capsys, path)
    assert code == 1 and "actual:   start at 2.000 s, release at 3.000 s" in out


def test_actions_start_with_the_first_user_and_release_with_the_last(files, capsys):
    path = files("""  - name: stop spans both behaviours
    topics:
""" + ODOM + """      /scan:
        type: sensor_msgs/LaserScan
        messages:
          - {at: 1.5 s, range_min: 1.0}
          - {at: 2.5 s, range_min: 0.0}
    expect:
      - {at: 1.5 s, start: stop}
      - {at: 3 s, release: stop}
      - {at: 1.5 s, start: 2}
      - {at: 2.5 s, release: behaviour 2}
""")
    code, out, err = run(capsys, path)
    assert code == 0, out + err


def test_node_samples_keep_left_out_values(files, capsys):
    path = files("""  - name: hot controller
    duration: 4 s
    nodes:
      controller:
        - {at: 0 s, alive: true, cpu: 20 %, memory: 50 MB}
        - {at: 1 s, cpu: 95 %}
        - {at: 2 s, memory: 60 MB}
        - {at: 3 s, cpu: 0.5}
    topics:
      /cmd_vel: {type: geometry_msgs/Twist, rate: 10 Hz, field: linear.x, values: "0x50"}
    expect:
      - {at: 1 s, start: 3}
      - {at: 3 s, release: 3}
      - {never: 4}
""")
    code, out, err = run(capsys, path)
    assert code == 0, out + err


def test_silence_and_duration(files, capsys):
    path = files("""  - name: silent cmd_vel
    duration: 3 s
    topics:
      /cmd_vel: {type: geometry_msgs/Twist, rate: 10 Hz, field: linear.x, values: "0x10 _x10 0x10"}
    expect:
      - {at: 1.4 s, start: 4}
      - {at: 2.0 s, release: 4}
      - {active: 4, from: 1.5 s, to: 1.95 s}
""")
    code, out, err = run(capsys, path)
    assert code == 0, out + err


def test_same_instant_is_one_message_later_entries_win(files, capsys):
    path = files("""  - name: merged
    topics:
      /scan:
        type: sensor_msgs/LaserScan
        rate: 1 Hz
        fields: {range_min: "1 1", range_max: "5 5"}
        messages:
          - {at: 1 s, range_min: 0.0}
    expect:
      - {at: 0 s, start: obstacle}
      - {at: 1 s, release: obstacle}
""")
    code, out, err = run(capsys, path)
    assert code == 0, out + err


def test_header_stamp_is_the_message_time_unless_set():
    from rubass.testing.messages import build, message_class

    cls = message_class("nav_msgs/Odometry")
    assert build(cls, [], 1.25).header.stamp.to_sec() == 1.25
    assert build(cls, [(("header",), {"stamp": 0})], 1.25).header.stamp.is_zero()


@pytest.mark.parametrize("body,line,text", [
    ("  - name: x\n    expect: [{at: 1 s, start: nobody}]\n", 4, "'nobody' is neither a behaviour's name"),
    ("  - name: x\n    expectt: []\n", 4, "unknown key 'expectt'"),
    ("  - name: x\n    topics:\n      /odom: {type: nav_msgs/Odometry, rate: 10 Hz, field: twist.linear.x, values: '1'}\n"
     "    expect: []\n", 5, "has no field 'linear'"),
    ("  - name: x\n    topics:\n      /odom: {type: nav_msgs/Odometri, messages: [{at: 1 s}]}\n    expect: []\n", 5,
     "nav_msgs/Odometri is not installed"),
    ("  - name: x\n    topics:\n      /odom:\n        type: nav_msgs/Odometry\n        messages:\n"
     "          - {at: 1 s, child_frame_id: 3}\n    expect: []\n", 8, "is a string"),
    ("  - name: x\n    expect: [{at: 1 parsec, start: 1}]\n", 4, "quantity in seconds"),
    ("  - name: x\n    expect: [{start: 1}]\n", 4, "start needs 'at'"),
    ("  - name: x\n    expect:\n      - {at: 1 s, start: 1\n", 6, "not valid YAML"),
    ("  - name: x\n    topics:\n      /odom: {type: nav_msgs/Odometry, rate: 10 Hz, field: twist.twist.linear.x, "
     "values: '1x3 zz'}\n    expect: []\n", 5, "'zz' is not a value"),
])
def test_bad_files_say_file_line_error_and_exit_2(files, capsys, body, line, text):
    path = files(body)
    code, out, err = run(capsys, path)
    assert code == 2
    assert f"{path}:{line}: error: " in err and text in err, err
    assert "Traceback" not in out + err


def test_bad_spec_is_reported_with_the_spec_error(files, write, capsys):
    write("robot.rbs", SPEC.replace("base.hot", "base.hott"))
    code, _, err = run(capsys, files("  - name: x\n    expect: []\n"))
    assert code == 2 and "robot.test.yaml:1: error: spec" in err and "has no rule 'hott'" in err


def test_junit_and_coverage(files, tmp_path, capsys):
    path = files("""  - name: good
    covers: [SR-1]
    topics:
""" + ODOM + """    expect:
      - {at: 2 s, start: overspeed}
      - {at: 3 s, release: overspeed}
  - name: bad
    expect:
      - {at: 1 s, start: obstacle}
""")
    out_xml = str(tmp_path / "out.xml")
    code, out, _ = run(capsys, path, "--junit", out_xml, "--coverage")
    assert code == 1
    suite = ET.parse(out_xml).getroot().find("testsuite")
    cases = suite.findall("testcase")
    assert [c.get("name") for c in cases] == ["good", "bad"]
    assert cases[0].find("failure") is None and cases[1].find("failure") is not None
    assert suite.get("failures") == "1"
    assert "rules never true: base.close, base.hot" in out
    assert "behaviours never started: obstacle, behaviour 3 (line 12)" in out


def test_command_line_exit_codes():
    r = subprocess.run([sys.executable, "-m", "rubass", "test", "/nonexistent.test.yaml"], cwd=ROOT,
                       capture_output=True, text=True)
    assert r.returncode == 2 and "/nonexistent.test.yaml: error: cannot read" in r.stderr
    assert r.stdout.strip().endswith("0 passed, 0 failed")


def test_docs_testing_md_examples_run_and_pass(tmp_path, capsys):
    """docs/testing.md: its spec and every test file on the page pass, as the page says."""
    import re
    import shutil

    text = open(os.path.join(ROOT, "docs", "testing.md"), encoding="utf-8").read()
    (spec,) = re.findall(r"```rubass\n(.*?)```", text, re.S)
    (tmp_path / "robot.rbs").write_text(spec)
    shutil.copy(os.path.join(ROOT, "docs", "examples", "actions.yaml"), tmp_path / "actions.yaml")
    files = [b for b in re.findall(r"```yaml\n(.*?)```", text, re.S) if b.startswith("spec:")]
    assert len(files) >= 2
    for k, body in enumerate(files):
        path = tmp_path / f"t{k}.test.yaml"
        path.write_text(body)
        code, out, err = run(capsys, str(path))
        assert code == 0, out + err
        assert "FAIL" not in out and not err


@pytest.mark.parametrize("body,text", [
    ("  - name: x\n    duration: .inf\n", "finite"),
    ("  - name: x\n    duration: 100000 h\n", "longer than a test may run"),
    ("  - name: x\n    topics:\n      /odom:\n        type: nav_msgs/Odometry\n        messages:\n"
     "          - {at: 1 s, header: {stamp: -5}}\n", "is a time"),
    ("  - name: x\n    - 3\n", "not valid YAML"),
    ("tests: 3\n", "duplicate key 'tests'"),
])
def test_more_bad_files(files, capsys, body, text):
    code, out, err = run(capsys, files(body))
    assert code == 2 and text in err and "Traceback" not in out + err, err


def test_a_test_without_expectations_passes(files, capsys):
    code, out, _ = run(capsys, files("  - name: inputs only\n    topics:\n" + ODOM))
    assert code == 0 and "PASS  inputs only" in out


def test_version_2_escalation_within_and_sectors(write, capsys):
    """active(), `within` and an array sector, through the test runner."""
    write("lib.yaml", "actions:\n  stop: {plugin: log, level: warn}\n  board_stop: {plugin: log, level: error}\n")
    write("esc.rbs", """import "lib.yaml";
action primitive stop, board_stop;
entity base { rules:
  too_fast: topic /odom.twist.twist.linear.x > 0.5 m/s;
  still_moving: abs(topic /odom.twist.twist.linear.x) > 0.05 m/s;
  near: min(topic /scan.ranges[0:2]) < 0.4 m;
}
overspeed: if (base.too_fast) then { stop; }
escalate: if ((active(stop) for 0.5 s) and base.still_moving) then { board_stop; }
if (base.near within 1 s) then { stop; }
""")
    path = write("esc.test.yaml", """spec: esc.rbs
tests:
  - name: ladder
    duration: 3 s
    topics:
      /odom: {type: nav_msgs/Odometry, rate: 10 Hz, field: twist.twist.linear.x, values: "0x5 0.6x5 0.3x10 0x10"}
      /scan:
        type: sensor_msgs/LaserScan
        messages:
          - {at: 0 s, ranges: [1, 1, 1], range_min: 0.1, range_max: 10}
          - {at: 0.2 s, ranges: [1, 0.3, 0.2], range_min: 0.1, range_max: 10}
          - {at: 0.3 s, ranges: [1, 1, 0.2], range_min: 0.1, range_max: 10}  # 0.2 m is outside [0:2]
    expect:
      - {at: 0.5 s, start: overspeed}
      - {at: 1.0 s, release: overspeed}
      - {at: 0.2 s, start: 3}
      - {at: 1.3 s, release: 3}              # near until 0.3 s, within 1 s
      - {at: 0.2 s, start: stop}
      - {at: 1.3 s, release: stop}
      - {at: 0.7 s, start: escalate}         # stop active for 0.5 s while moving
      - {at: 1.3 s, release: escalate}
""")
    code, out, err = run(capsys, path)
    assert code == 0, out + err


def test_types_not_installed_come_from_the_system_model(write, capsys):
    write("lib.yaml", LIB)
    write("robot.model.yaml", """rubass_model: 1
topics:
  /bms: my_robot_msgs/Battery
definitions:
  my_robot_msgs/Battery: |
    std_msgs/Header header
    float64 voltage
    my_robot_msgs/Cell[] cells
  my_robot_msgs/Cell: |
    float64 voltage
    string name
""")
    write("b.rbs", """import "lib.yaml";
action primitive stop;
entity bat { rules: low: topic /bms.voltage < 11 and stamp_age(topic /bms) < 1 s;
                    weak: min(topic /bms.cells[*].voltage) < 3; }
low_battery: if (bat.low or bat.weak) then { stop; }
""")
    body = """spec: b.rbs
model: robot.model.yaml
tests:
  - name: low battery, then a weak cell
    topics:
      /bms:
        type: my_robot_msgs/Battery
        messages:
          - {at: 0.5 s, voltage: 12.0, cells: [{voltage: 4.0, name: a}]}
          - {at: 1 s, voltage: 10.5}
          - {at: 2 s, voltage: 12.0, cells: [{voltage: 2.5, name: a}]}
          - {at: 3 s, voltage: 12.0, cells: [{voltage: 4.0, name: a}]}
    expect:
      - {at: 1 s, start: low_battery}
      - {at: 3 s, release: low_battery}
"""
    code, out, err = run(capsys, write("b.test.yaml", body))
    assert code == 0, out + err
    code, _, err = run(capsys, write("c.test.yaml", body.replace("model: robot.model.yaml\n", "")))
    assert code == 2 and "my_robot_msgs/Battery is not installed" in err
    code, _, err = run(capsys, write("d.test.yaml", body.replace("voltage: 10.5", "voltag: 10.5")))
    assert code == 2 and "has no field 'voltag'" in err


def test_a_test_file_that_is_no_text_names_the_line_of_the_bad_byte(tmp_path):
    """TESTING.md: errors are FILE:LINE: error: …; bad bytes were reported with Python's codec wording."""
    path = tmp_path / "bin.test.yaml"
    path.write_bytes(b"tests:\n  - name: x\n    expect: []  # \xff\n")
    r = subprocess.run([sys.executable, "-m", "rubass", "test", str(path)], cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 2
    assert f"{path}:3: error: test file is not UTF-8 text: invalid byte 0xff" in r.stderr, r.stderr
    assert "codec" not in r.stderr


def test_stamp_age_of_a_type_without_a_header_is_unknown_not_an_error(write, capsys):
    """§11: stamp_age is unknown for a type with no header.stamp. `rubass test` refused the file
    (exit 2: 'reads /x.header.stamp', a field the user never wrote)."""
    write("lib.yaml", LIB)
    write("s.rbs", 'import "lib.yaml";\naction primitive stop, warn;\n'
                   "entity e { rules:\n  stale: stamp_age(topic /x) > 0.5 s;\n  known: not (stamp_age(topic /x) > 0.5 s);\n"
                   "  high: topic /x.data > 1;\n}\n"
                   "if (e.stale or e.known) then { stop; }\nif (e.high) then { warn; }\n")
    path = write("s.test.yaml", "spec: s.rbs\ntests:\n  - name: unknown\n    duration: 3 s\n    topics:\n"
                                "      /x: {type: std_msgs/Float64, messages: [{at: 1 s, data: 2}]}\n"
                                "    expect:\n      - {at: 1 s, start: 2}\n      - {never: 1}\n")
    code, out, err = run(capsys, path)
    assert code == 0, out + err
    assert "PASS" in out and "header.stamp" not in err


def test_stamp_age_of_a_type_without_a_header_is_a_warning_with_a_model(tmp_path):
    from rubass.lang.loader import check_source
    from rubass.lang.msgdef import Registry, parse_msg
    from rubass.lang.source import Source
    from rubass.lang.sysmodel import SystemModel

    registry = Registry()
    registry.add(parse_msg("std_msgs/Float64", "float64 data\n"))
    checked = check_source(Source("s.rbs", "entity e { rules: s: stamp_age(topic /x) > 0.5 s; }\n"),
                           model=SystemModel({"/x": "std_msgs/Float64"}, None, registry))
    assert [f"{w.span.line}:{w.span.col}: {w.message}" for w in checked.warnings] == [
        "1:32: stamp_age(topic /x) is always unknown: the topic's type has no header.stamp (use age() for the "
        "time since its last message)"]


def test_a_file_outside_the_current_directory_is_shown_by_its_absolute_path(tmp_path):
    from rubass.testing.results import shown_path

    outside = str(tmp_path / "x.test.yaml")
    assert shown_path(outside) == outside  # was '../../tmp/…' from the project folder
    assert shown_path(os.path.join(os.getcwd(), "a", "b.yaml")) == os.path.join("a", "b.yaml")
