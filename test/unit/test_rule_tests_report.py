"""`rubass report`: one self-contained page with the matrix and its gaps, tests, bags with witnesses."""
import os
import re

import pytest

from rubass.cli import main
from rubass.report.bench import from_json_lines, from_readme

from conftest import ROOT

LIB = """actions:
  stop: {plugin: log, level: warn}
"""
SPEC = """import "lib.yaml";
action primitive stop;
@hazard("H1") entity base {
  rules:
    @id("SR-1") @title("Speed limit") @ref("ISO 13482 (example)")
    too_fast: topic /odom.twist.twist.linear.x > 0.5 m/s for 1 s;
    @id("SR-2") @hazard("H2")
    untested: topic /odom.pose.pose.position.x > 100 m;
}
@id("SF-1") overspeed: if (base.too_fast) then { stop; }
far: if (base.untested) then { stop; }
"""
TESTS = """spec: robot.rbs
tests:
  - name: overspeed stops
    covers: [SR-1, H1]
    topics:
      /odom: {type: nav_msgs/Odometry, rate: 10 Hz, field: twist.twist.linear.x, values: "0x10 0.6x20 0x10"}
    expect:
      - {at: 2 s, start: overspeed}
      - {at: 3 s, release: overspeed}
  - name: a wrong expectation
    covers: [SR-1]
    topics:
      /odom: {type: nav_msgs/Odometry, rate: 10 Hz, field: twist.twist.linear.x, values: "0x10 0.6x20"}
    expect:
      - {at: 1.5 s, start: overspeed}
"""
HAZARDS = """hazards:
  - {id: H1, title: Collision at speed, severity: S2}
  - {id: H2, title: Leaving the area}
  - {id: H3, title: Tip-over, severity: S2}
"""


@pytest.fixture
def inputs(write):
    write("lib.yaml", LIB)
    return write("robot.rbs", SPEC), write("robot.test.yaml", TESTS), write("hazards.yaml", HAZARDS)


def bag(path):
    rosbag = pytest.importorskip("rosbag")
    import rospy
    from nav_msgs.msg import Odometry

    with rosbag.Bag(path, "w") as b:
        for k in range(30):
            m = Odometry()
            m.twist.twist.linear.x = 0.62 if k >= 5 else 0.0
            b.write("/odom", m, rospy.Time.from_sec(50 + 0.1 * k))
    return path


def test_report_is_one_self_contained_page_with_the_gaps(inputs, tmp_path, capsys):
    spec, tests, hazards = inputs
    out = str(tmp_path / "report.html")
    code = main(["report", spec, "--tests", tests, "--hazards", hazards, "--bag", bag(str(tmp_path / "r.bag")),
                 "-o", out])
    printed = capsys.readouterr().out
    assert code == 1  # a test fails: the report is written, and the exit says so
    assert "report written to" in printed and "1 test passed, 1 failed" in printed
    html = open(out, encoding="utf-8").read()
    assert html.startswith("<!DOCTYPE html>") and html.rstrip().endswith("</html>")
    assert not re.search(r"<(script|link|img)\b", html)  # nothing fetched: readable offline
    for text in ("SR-1", "Speed limit", "ISO 13482 (example)", "Collision at speed", "severity: S2"):
        assert text in html
    rows = re.findall(r"<tr><td><b>(H\d)</b>.*?</tr>", html, re.S)
    assert rows[:3] == ["H1", "H2", "H3"]
    h2 = re.search(r"<tr><td><b>H2</b>.*?</tr>", html, re.S).group(0)
    assert "no test" in h2  # base.untested was never true and no test covers SR-2
    h3 = re.search(r"<tr><td><b>H3</b>.*?</tr>", html, re.S).group(0)
    assert "no rule" in h3
    h1 = re.search(r"<tr><td><b>H1</b>.*?</tr>", html, re.S).group(0)
    assert "test &#x27;a wrong expectation&#x27; fails" in h1
    assert "FAIL" in html and "expected: start at 1.500 s" in html
    assert "<svg" in html and "/odom.twist.twist.linear.x = 0.62" in html  # the bag's start explains itself
    assert "1 s + ≤" in html  # the rule's own time beside the monitor's measured reaction


def test_report_without_tests_or_bags_marks_every_rule_untested(inputs, tmp_path, capsys):
    spec, _, _ = inputs
    out = str(tmp_path / "r.html")
    assert main(["report", spec, "-o", out]) == 0
    html = open(out, encoding="utf-8").read()
    assert "No test file was given" in html and html.count("no test") >= 2


def test_report_bad_inputs_are_one_line_errors(inputs, tmp_path, capsys, write):
    spec, _, _ = inputs
    bad = write("bad.yaml", "hazards: 3\n")
    assert main(["report", spec, "--hazards", bad, "-o", str(tmp_path / "x.html")]) == 1
    assert "expected 'hazards:'" in capsys.readouterr().err
    assert main(["report", spec, "--bag", str(tmp_path / "none.bag"), "-o", str(tmp_path / "y.html")]) == 1
    assert "no such file" in capsys.readouterr().err
    assert main(["report", spec, "-o", str(tmp_path / "bad.yaml" / "dir" / "z.html")]) == 1  # under a file
    assert "cannot write" in capsys.readouterr().err


def test_measured_reaction_from_the_benchmark(tmp_path):
    readme = from_readme()
    if readme is None:
        pytest.skip("bench/README.md is absent")
    assert readme.worst_ms >= readme.p99_ms >= readme.p50_ms > 0
    lines = tmp_path / "bench.jsonl"
    lines.write_text('{"benchmark": "reaction", "rubass": {"p50_ms": 0.3, "p99_ms": 2.0, "max_ms": 4.5}}\n'
                     '{"benchmark": "reaction", "rubass": {"p50_ms": 0.2, "p99_ms": 1.0, "max_ms": 6.25}}\n'
                     'not json\n')
    r = from_json_lines(str(lines))
    assert (r.worst_ms, r.p99_ms, r.cases) == (6.25, 2.0, 2)


def test_shipped_example_tests_pass_with_full_coverage(capsys):
    files = [os.path.join(ROOT, "config", "tests", f) for f in ("kobuki.test.yaml", "frobit.test.yaml")]
    code = main(["test", *files, "--coverage"])
    out = capsys.readouterr().out
    assert code == 0, out
    assert out.count("rules never true: none") == 2 and out.count("ids no test covers: none") == 2


def test_the_coverage_names_its_spec_as_the_docs_show(capsys, monkeypatch):
    """docs/testing.md: `coverage of config/frobit.rbs (7 tests):`, relative to the current folder
    (it printed the absolute path)."""
    monkeypatch.chdir(ROOT)
    assert main(["test", os.path.join("config", "tests", "frobit.test.yaml"), "--coverage"]) == 0
    assert "coverage of config/frobit.rbs (7 tests):" in capsys.readouterr().out
