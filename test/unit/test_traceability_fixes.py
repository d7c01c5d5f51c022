"""Traceability fixes of issue 16: an entity's @id is a known id, duplicate ids in source order, bad
report inputs exit 1, one gap is "1 gap"."""
import os
import re

import pytest

from rubass.cli import main
from rubass.lang import SpecError, check_text
from rubass.testing.coverage import traced, unknown_covers

from conftest import ROOT

LIB = """actions:
  stop: {plugin: log, level: warn}
"""
SPEC = """import "lib.yaml";
action primitive stop;
@id("E-1") @hazard("H1") entity base {
  rules:
    too_fast: topic /odom.twist.twist.linear.x > 0.5 m/s;
    @id("SR-2") far: topic /odom.pose.pose.position.x > 100 m;
}
@id("SF-1") overspeed: if (base.too_fast) then { stop; }
far: if (base.far) then { stop; }
"""
TEST = """spec: e.rbs
tests:
  - name: overspeed stops
    covers: [{covers}]
    topics:
      /odom: {{type: nav_msgs/Odometry, rate: 10 Hz, field: twist.twist.linear.x, values: "0x10 0.6x20"}}
    expect:
      - {{at: 1 s, start: overspeed}}
"""


@pytest.fixture
def spec_path(write):
    write("lib.yaml", LIB)
    return write("e.rbs", SPEC)


def test_an_entity_id_is_a_known_id(spec_path):
    spec = check_text(SPEC, spec_path)
    ids, _ = traced(spec)
    assert ids == ["E-1", "SR-2", "SF-1"]
    assert unknown_covers(spec, ["E-1", "E-2"]) == ["E-2"]
    assert spec.rule("base.too_fast").attrs.get("id") is None  # the rule does not take it as its own (§15)


def test_coverage_lists_an_entity_id_no_test_covers(spec_path, write, capsys):
    tests = write("e.test.yaml", TEST.format(covers="SF-1"))
    assert main(["test", "--coverage", tests]) == 0
    out = capsys.readouterr()
    assert "ids no test covers: E-1, SR-2" in out.out
    tests = write("e.test.yaml", TEST.format(covers="E-1"))
    assert main(["test", "--coverage", tests]) == 0
    out = capsys.readouterr()
    assert "ids no test covers: SR-2, SF-1" in out.out and "which is no @id" not in out.err + out.out


def test_report_shows_the_entity_id_and_counts_its_tests(spec_path, write, tmp_path, capsys):
    tests = write("e.test.yaml", TEST.format(covers="E-1, H1"))  # the rule by its entity's id, and its hazard
    out = str(tmp_path / "r.html")
    assert main(["report", spec_path, "--tests", tests, "-o", out]) == 0
    html = open(out, encoding="utf-8").read()
    rules = html.split("<h2 id='rules'>", 1)[1].split("<h2", 1)[0]
    too_fast = re.search(r"<tr><td><code>base.too_fast</code></td><td>(.*?)</td>", rules).group(1)
    assert too_fast.startswith("E-1") and "entity base" in too_fast  # inherited, marked as the entity's
    far = re.search(r"<tr><td><code>base.far</code></td><td>(.*?)</td>", rules).group(1)
    assert far == "SR-2"  # its own id
    matrix = html.split("<h2 id='matrix'>", 1)[1].split("<h2", 1)[0]
    row = re.search(r"<tr><td><b>H1</b>.*?base.too_fast.*?</tr>", matrix, re.S).group(0)
    assert "E-1" in row and "overspeed stops" in row and "covered" in row


def check_errors(text, tmp_path):
    path = str(tmp_path / "dupid2.rbs")
    with open(path, "w") as fh:
        fh.write(text)
    with pytest.raises(SpecError) as exc:
        check_text(text, path, [os.path.join(ROOT, "docs", "examples", "actions.yaml")])
    return exc.value.render()


def test_duplicate_id_is_reported_at_the_later_place(tmp_path):
    text = ('import "actions.yaml";\naction primitive stop;\n@id("A") entity base { rules: r: topic /v.x > 1; }\n'
            '@id("A") if (base.r) then { stop; }\n@id("A") if (base.r) then { stop; }\n')
    rendered = check_errors(text, tmp_path)
    errors = [line for line in rendered.splitlines() if "duplicate id" in line]
    assert len(errors) == 2
    assert errors[0].startswith(f"{tmp_path}/dupid2.rbs:4:1: error: duplicate id \"A\"; first given at "
                                f"{tmp_path}/dupid2.rbs:3:1")
    assert errors[1].startswith(f"{tmp_path}/dupid2.rbs:5:1:") and errors[1].endswith("dupid2.rbs:3:1")


def test_duplicate_id_of_a_rule_and_a_later_entity(tmp_path):
    text = ('import "actions.yaml";\naction primitive stop;\nentity a { rules: @id("X") r: topic /v.x > 1; }\n'
            '@id("X") entity b { rules: q: topic /v.x > 2; }\nif (a.r or b.q) then { stop; }\n')
    (error,) = [line for line in check_errors(text, tmp_path).splitlines() if "duplicate id" in line]
    assert error.startswith(f"{tmp_path}/dupid2.rbs:4:1:") and error.endswith("dupid2.rbs:3:19")


@pytest.mark.parametrize("text, why", [
    ("not json\n", "line 1 is not JSON"),
    ('{"a":1}\n', "line 1 holds no reaction figures"),
    ("", "the file is empty"),
])
def test_report_with_an_unusable_bench_file_exits_1(spec_path, write, tmp_path, capsys, text, why):
    bench = write("bench.jsonl", text)
    out = str(tmp_path / "r.html")
    assert main(["report", spec_path, "--bench", bench, "-o", out]) == 1
    err = capsys.readouterr().err
    assert f"rubass report: error: {bench}: no reaction figures ({why})" in err
    assert "bench/reaction.py" in err and not os.path.exists(out)


def test_report_with_a_bench_file_missing_figures_or_absent(spec_path, write, tmp_path, capsys):
    bench = write("bench.jsonl", '{"benchmark": "reaction", "rubass": {"max_ms": 3}}\n')
    assert main(["report", spec_path, "--bench", bench, "-o", str(tmp_path / "r.html")]) == 1
    assert f"{bench}:1: a reaction needs the numbers max_ms, p99_ms and p50_ms" in capsys.readouterr().err
    absent = str(tmp_path / "none.jsonl")
    assert main(["report", spec_path, "--bench", absent, "-o", str(tmp_path / "r.html")]) == 1
    assert f"{absent}: cannot read: No such file or directory" in capsys.readouterr().err


def test_a_hazard_given_twice_in_the_risk_table_is_an_error_with_its_line(spec_path, write, tmp_path, capsys):
    risk = write("risk.yaml", "hazards:\n  - {id: H1, title: Collision}\n  - id: H2\n    title: Tip-over\n"
                              "  - {id: H1, title: Again}\n")
    assert main(["report", spec_path, "--hazards", risk, "-o", str(tmp_path / "r.html")]) == 1
    assert f"{risk}:5:10: error: hazard H1 is given twice; first at {risk}:2:10" in capsys.readouterr().err


def test_one_gap_and_one_hazard_are_singular(spec_path, write, tmp_path, capsys):
    tests = write("e.test.yaml", TEST.format(covers="E-1, H1"))  # the rule by its entity's id, and its hazard
    out = str(tmp_path / "r.html")
    assert main(["report", spec_path, "--tests", tests, "-o", out]) == 0
    assert "1 gap in the matrix" in capsys.readouterr().out  # base.far: no test
    html = open(out, encoding="utf-8").read()
    assert "<b class='fail'>1</b>gap in the matrix" in html and "<b>1</b>hazard</div>" in html
