"""`rubass test`: fixes from an acceptance run (node spellings, tests that expect nothing, failure
times and tolerance, xN with N=0, tolerance on never, integers out of range)."""
import xml.etree.ElementTree as ET

import pytest

from rubass.cli import main
from rubass.report.evidence import covering
from rubass.testing.coverage import coverage
from rubass.testing.results import run_file
from rubass.testing.series import SeriesError, expand

LIB = """actions:
  stop: {plugin: log, level: warn}
  warn: {plugin: log, level: warn}
"""

NODE_SPEC = """import "lib.yaml";
action primitive stop, warn;
entity base: controller {
  rules:
    dead: not alive(node controller);
    fat: memory(node /controller) > 100 MB;
}
b_dead: if (base.dead) then { warn; }
b_fat: if (base.fat) then { warn; }
"""

SPEC = """import "lib.yaml";
action primitive stop, warn;
entity base: controller {
  rules:
    @id("SR-1") @hazard("H1")
    too_fast: topic /odom.twist.twist.linear.x > 0.5 m/s for 1 s;
}
overspeed: if (base.too_fast) then { stop; }
"""

ODOM = """      /odom: {type: nav_msgs/Odometry, rate: 10 Hz, field: twist.twist.linear.x, values: "0x10 0.6x20 0x10"}
"""


def run(capsys, *args):
    code = main(["test", *args])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def robot(write):
    write("lib.yaml", LIB)
    write("robot.rbs", SPEC)
    return lambda tests: write("robot.test.yaml", "spec: robot.rbs\ntests:\n" + tests)


@pytest.mark.parametrize("spelling", ["/controller", "controller"])
def test_node_samples_reach_every_spelling_of_the_node(write, capsys, spelling):
    write("lib.yaml", LIB)
    write("nd.rbs", NODE_SPEC)
    path = write("nd.test.yaml", f"""spec: nd.rbs
tests:
  - name: both spellings
    duration: 4 s
    nodes:
      {spelling}:
        - {{at: 0 s, alive: true, memory: 50 MB}}
        - {{at: 1 s, memory: 0.2 GB}}
        - {{at: 2 s, alive: false}}
        - {{at: 3 s, alive: true, memory: 50000000}}
    expect:
      - {{at: 1 s, start: b_fat}}
      - {{at: 2 s, release: b_fat}}  # dead at 2 s: its memory unknown, as live
      - {{at: 2 s, start: b_dead}}
      - {{at: 3 s, release: b_dead}}
""")
    code, out, err = run(capsys, path)
    assert code == 0 and "PASS  both spellings" in out, out + err
    assert "warning" not in err


def test_samples_under_two_spellings_are_one_node(write, capsys):
    """A value one spelling's sample leaves out keeps the other spelling's: it is one node."""
    write("lib.yaml", LIB)
    write("nd.rbs", NODE_SPEC)
    path = write("nd.test.yaml", """spec: nd.rbs
tests:
  - name: merged
    duration: 3 s
    nodes:
      controller:
        - {at: 0 s, alive: true, memory: 0.2 GB}
      /controller:
        - {at: 1 s, memory: 50 MB}
    expect:
      - {at: 0 s, start: b_fat}
      - {at: 1 s, release: b_fat}
      - {never: b_dead}
""")
    code, out, err = run(capsys, path)
    assert code == 0, out + err


def test_a_test_that_expects_nothing_warns_and_its_covers_do_not_count(robot, capsys):
    path = robot("  - name: inputs only\n    covers: [SR-1, H1]\n    topics:\n" + ODOM)
    code, out, err = run(capsys, path, "--coverage")
    assert code == 0 and "PASS  inputs only" in out
    assert "robot.test.yaml:3: warning: test 'inputs only' expects nothing, so it proves nothing; its covers " \
           "do not count" in err, err
    assert "not counted" in out
    assert "ids no test covers: SR-1" in out and "hazards no test covers: H1" in out, out
    result = run_file(path)
    assert covering(result.outcomes, ["H1"]) == [] and covering(result.outcomes, ["SR-1"]) == []
    assert coverage(result.spec, result.outcomes).hazards_untested == ["H1"]


def test_a_test_that_expects_something_still_covers(robot, capsys):
    path = robot("  - name: real\n    covers: [SR-1, H1]\n    topics:\n" + ODOM + "    expect:\n"
                 "      - {at: 2 s, start: overspeed}\n      - {at: 3 s, release: overspeed}\n")
    code, out, err = run(capsys, path, "--coverage")
    assert code == 0 and "warning" not in err and "not counted" not in out
    assert "ids no test covers: none" in out and "hazards no test covers: none" in out
    result = run_file(path)
    assert [o.name for o in covering(result.outcomes, ["H1"])] == ["real"]


def test_failure_times_show_the_difference_and_the_tolerance(robot, capsys, tmp_path):
    path = robot("  - name: late\n    topics:\n" + ODOM + "    expect:\n"
                 "      - {at: 2.0012 s, start: overspeed}\n      - {at: 3 s, release: overspeed}\n"
                 "  - name: fine\n    topics:\n" + ODOM + "    expect:\n"
                 "      - {at: 2.0005 s, start: overspeed, tolerance: 0.4 ms}\n      - {at: 3 s, release: overspeed}\n"
                 "  - name: near\n    topics:\n" + ODOM + "    expect:\n"
                 "      - {at: 1.999 s, start: overspeed}\n      - {at: 3 s, release: overspeed}\n"
                 "    tolerance: 0.5 ms\n")
    junit = str(tmp_path / "j.xml")
    code, out, _ = run(capsys, path, "--junit", junit)
    assert code == 1
    assert "expected: start at 2.0012 s, release at 3.0000 s (each ± 1 ms)" in out, out
    assert "actual:   start at 2.0000 s, release at 3.0000 s" in out
    assert "expected: start at 2.0005 s ± 0.4 ms, release at 3.0000 s ± 1 ms" in out
    assert "expected: start at 1.9990 s, release at 3.0000 s (each ± 0.5 ms)" in out
    assert "2.001 s" not in out and "2.000 s" not in out
    messages = [f.get("message") for f in ET.parse(junit).getroot().iter("failure")]
    assert any("start at 2.0012 s" in m and "± 1 ms" in m and "start at 2.0000 s" in m for m in messages), messages


def test_a_difference_hidden_at_the_tolerances_precision_gets_more_digits(robot, capsys):
    """2.001 against 2.0021 would print 2.001 against 2.002 at ms: within 1 ms though 1.1 ms off."""
    path = robot("  - name: off\n    topics:\n" + ODOM + "    expect:\n"
                 "      - {at: 1.9989 s, start: overspeed}\n      - {at: 3 s, release: overspeed}\n")
    code, out, _ = run(capsys, path)
    assert code == 1 and "expected: start at 1.9989 s" in out and "actual:   start at 2.0000 s" in out, out


def test_series_n_of_zero_is_an_error():
    for words in ("0.6x0", "0+0.1x0", "'a'x0", "_x0"):
        with pytest.raises(SeriesError, match="at least 1"):
            expand(words)
    assert expand("0.6x1") == [0.6]


def test_series_n_of_zero_in_a_file_is_an_error_at_its_line(robot, capsys):
    path = robot("  - name: zero\n    topics:\n      /odom:\n        type: nav_msgs/Odometry\n        rate: 10 Hz\n"
                 "        field: twist.twist.linear.x\n        values: \"0.6x0 0x5\"\n"
                 "    expect:\n      - {never: overspeed}\n")
    code, _, err = run(capsys, path)
    assert code == 2 and "robot.test.yaml:9: error:" in err and "at least 1" in err, err


def test_tolerance_on_never_is_an_error_and_on_active_widens(robot, capsys):
    path = robot("  - name: never\n    topics:\n" + ODOM + "    expect:\n"
                 "      - {never: overspeed, tolerance: 5 ms}\n")
    code, _, err = run(capsys, path)
    assert code == 2 and "robot.test.yaml:7: error: 'tolerance' does not go with never" in err, err
    path = robot("  - name: active\n    topics:\n" + ODOM + "    expect:\n"
                 "      - {active: overspeed, from: 1.99 s, to: 3.01 s, tolerance: 20 ms}\n")
    assert run(capsys, path)[0] == 0
    path = robot("  - name: active\n    topics:\n" + ODOM + "    expect:\n"
                 "      - {active: overspeed, from: 1.99 s, to: 3.01 s}\n")
    code, out, _ = run(capsys, path)
    assert code == 1 and "[1.990, 3.010] s ± 1 ms" in out, out


def test_an_integer_out_of_range_names_the_element_and_the_value(write, capsys):
    write("lib.yaml", LIB)
    write("d.rbs", 'import "lib.yaml";\naction primitive warn;\nentity e: x {\n  rules:\n'
                   '    r: topic /diag.status[0].level > 1;\n    u: topic /u.data > 1;\n}\n'
                   'if (e.r) then { warn; }\nif (e.u) then { warn; }\n')
    path = write("d.test.yaml", """spec: d.rbs
tests:
  - name: out of range
    topics:
      /diag:
        type: diagnostic_msgs/DiagnosticArray
        messages:
          - {at: 0 s, status: [{level: 1}, {level: 300}]}
      /u:
        type: std_msgs/UInt8
        messages:
          - {at: 0 s, data: -1}
    expect:
      - {never: 1}
""")
    code, out, err = run(capsys, path)
    assert code == 2, out + err
    assert "d.test.yaml:8: error: /diag (diagnostic_msgs/DiagnosticArray): status[1].level is a byte: 300 is out " \
           "of range -128 to 127" in err, err
    assert "d.test.yaml:12: error:" in err and "data is a uint8: -1 is out of range 0 to 255" in err, err
    assert "width" not in err and "Traceback" not in err


def test_digits_grow_until_a_time_outside_its_tolerance_reads_outside():
    from rubass.testing.cases import Expect
    from rubass.testing.runner import _shown_digits

    exps = [Expect("start", "x", 1, at=0.1)]
    # 0.1011 s against 0.100 s at ms would read 1 ms apart, within 1 ms, though 1.1 ms apart
    assert _shown_digits([("start", 0.1011)], exps, 0.001) == 4
    assert _shown_digits([("start", 0.1)], exps, 0.001) == 3
    assert _shown_digits([("start", 0.1)], [Expect("start", "x", 1, at=0.1, tolerance=0.0004)], 0.001) == 4
