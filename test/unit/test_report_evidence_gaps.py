"""`rubass report`: defects an acceptance tester reproduced, each pinned down.

Rules tracing to no hazard were left out of the matrix ("0 gaps"); a test file of another spec passed
silently with exit 0; the developers' benchmark figures were called "measured on this machine"; `-o` into
a folder that did not exist failed; the reaction of `not (age(…) <= 1 s)` read "immediate" on the page.
"""
import os
import re

import pytest

from rubass.cli import main

from conftest import ROOT

LIB = "actions:\n  stop: {plugin: log, level: warn}\n"
SPEC = """import "lib.yaml";
action primitive stop;
entity gps {
  rules:
    @id("SR-1") lost: not (age(topic /fix) <= 1 s);
    @id("SR-2") @hazard("H1") far: topic /fix.latitude > 50 and gps.near;
    near: topic /fix.longitude > 3;
}
@id("SF-1") lost_fix: if (gps.lost) then { stop; }
@id("SF-2") away: if (gps.far) then { stop; }
"""
OTHER = """import "lib.yaml";
action primitive stop;
entity base { rules: @id("X-1") too_fast: topic /odom.twist.twist.linear.x > 0.5 m/s; }
if (base.too_fast) then { stop; }
"""
OTHER_TESTS = """spec: other.rbs
tests:
  - name: stops
    covers: [X-1]
    topics:
      /odom: {type: nav_msgs/Odometry, rate: 10 Hz, field: twist.twist.linear.x, values: "0x5 0.6x5"}
    expect:
      - {at: 0.5 s, start: 1}
"""


@pytest.fixture
def spec(write):
    write("lib.yaml", LIB)
    write("other.rbs", OTHER)
    return write("gps.rbs", SPEC)


def report(capsys, *args):
    code = main(["report", *args])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_a_rule_with_no_hazard_is_a_gap_in_the_matrix_and_the_summary(spec, tmp_path, capsys):
    out = str(tmp_path / "r.html")
    code, printed, _ = report(capsys, spec, "-o", out)
    assert code == 0
    assert "1 rule traces to no hazard" in printed
    html = open(out, encoding="utf-8").read()
    row = re.search(r"<tr><td><b class='fail'>no hazard</b>.*?</tr>", html, re.S).group(0)
    assert "gps.lost" in row and "traces to no hazard" in row and "no test covers SR-1" in row
    assert "1 rule traces to no hazard" in html  # on the summary card
    # gps.near has no @hazard of its own, but gps.far (H1) is built on it: it traces to H1, no row of its own
    assert html.count("<b class='fail'>no hazard</b>") == 1
    gaps = int(re.search(r"<b class='fail'>(\d+)</b>gaps? in the matrix", html).group(1))
    assert gaps >= 2  # H1's rule (no test) and gps.lost


def test_the_shipped_specs_have_no_rule_without_a_hazard(tmp_path, capsys):
    """frobit's `commanded` rules carry no @hazard but serve rules that do: not gaps."""
    for robot in ("kobuki", "frobit"):
        out = str(tmp_path / f"{robot}.html")
        report(capsys, os.path.join(ROOT, "config", f"{robot}.rbs"), "-o", out)
        assert "no hazard</b>" not in open(out, encoding="utf-8").read()


def test_a_test_file_of_another_spec_is_an_error_not_silent_evidence(spec, write, tmp_path, capsys):
    tests = write("other.test.yaml", OTHER_TESTS)
    out = str(tmp_path / "r.html")
    code, printed, err = report(capsys, spec, "--tests", tests, "-o", out)
    assert code == 1
    assert tests in err and "other.rbs" in err and "not evidence for this spec" in err
    assert "1 test file of another spec not counted" in printed
    html = open(out, encoding="utf-8").read()
    assert "not counted as evidence" in html and "1 file(s) of another spec not counted" in html


def test_the_default_reaction_says_whose_figures_they_are(spec, tmp_path, capsys):
    out = str(tmp_path / "r.html")
    _, _, err = report(capsys, spec, "-o", out)
    html = open(out, encoding="utf-8").read()
    if "no benchmark figures" in html:
        pytest.skip("bench/README.md has no reaction table")
    assert "measured on this machine" not in html.replace("not measured on this machine", "")
    assert "the developers&#x27; figures" in html or "the developers' figures" in html
    assert "not measured on this machine" in html and "--bench" in html and "bench/reaction.py" in html
    assert "not this machine's" in err and "--bench" in err


def test_a_bench_file_is_named_as_the_source(spec, write, tmp_path, capsys):
    bench = write("reaction.jsonl", '{"benchmark": "reaction", "rubass": {"p50_ms": 0.3, "p99_ms": 2.0, '
                                    '"max_ms": 4.5}}\n')
    out = str(tmp_path / "r.html")
    _, _, err = report(capsys, spec, "--bench", bench, "-o", out)
    html = open(out, encoding="utf-8").read()
    assert "≤ 4.5 ms" in html and "reaction.jsonl" in html
    assert "developers" not in html and "developers" not in err


def test_the_output_folder_is_created(spec, tmp_path, capsys):
    out = tmp_path / "out" / "report" / "gps.html"
    code, printed, err = report(capsys, spec, "-o", str(out))
    assert code == 0, err
    assert out.is_file() and "report written to" in printed


def test_an_output_folder_that_cannot_be_made_is_one_clear_line(spec, write, tmp_path, capsys):
    blocker = write("a-file", "x")
    code, _, err = report(capsys, spec, "-o", os.path.join(blocker, "r.html"))
    assert code == 1 and "cannot create its folder" in err and "Traceback" not in err


def test_a_negated_age_has_its_time_on_the_page(spec, tmp_path, capsys):
    out = str(tmp_path / "r.html")
    report(capsys, spec, "-o", out)
    html = open(out, encoding="utf-8").read()
    row = re.search(r"<tr><td><code>gps.lost</code>.*?</tr>", html, re.S).group(0)
    assert "<td>1 s" in row and "immediate" not in row


def test_the_docs_cite_the_vendored_contract_and_the_demo():
    text = open(os.path.join(ROOT, "docs", "report.md"), encoding="utf-8").read()
    assert "(spec/LANGUAGE.md" in text
    assert not re.search(r"(?<!spec/)LANGUAGE\.md §", text)
    demo = text.index("tools/demo.sh")
    assert demo < text.index("out/experiments/runs/CPU/0/run.bag")
    assert "not measured on this machine" in text and "traces to no hazard" in text
