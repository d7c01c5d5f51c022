"""The report's reaction figures are upper bounds or absent: a benchmark case whose violations did
not all get their own stop bounds nothing; a printed figure is rounded up, never down; a latched
action's `not active()` has no time by design (only ~reset releases it)."""
import re

import pytest

from rubass.cli import main
from rubass.lang import check_text
from rubass.report.bench import BenchError, from_json_lines
from rubass.report.design import design, up
from rubass.lang import ast

CASE = ('{{"benchmark": "reaction", "rate_hz": 100, "background_load": false, '
        '"rubass": {{"p50_ms": 0.5, "p99_ms": 0.9, "max_ms": {max}}}, "rubass_unanswered": {missed}, '
        '"rubass_extra_stops": {extra}}}\n')


def _bench(write, *cases):
    return write("reaction.jsonl", "".join(CASE.format(**c) for c in cases))


def test_a_clean_case_is_its_own_bound(write):
    r = from_json_lines(_bench(write, dict(max=1.2, missed=0, extra=0), dict(max=3.4, missed=0, extra=0)))
    assert (r.worst_ms, r.cases) == (3.4, 2)


@pytest.mark.parametrize("bad,why", [
    (dict(max=1.2, missed=50, extra=0), "has 50 violations that got no stop"),
    (dict(max=1.2, missed=0, extra=1), "has 1 extra stops"),
    (dict(max="null", missed=0, extra=0), "measured no reaction"),
    (dict(max="NaN", missed=0, extra=0), "not a finite, non-negative number"),
    (dict(max=-2, missed=0, extra=0), "not a finite, non-negative number"),
])
def test_a_case_that_bounds_nothing_is_an_error_not_skipped(write, bad, why):
    path = _bench(write, dict(max=1.2, missed=0, extra=0), bad)
    with pytest.raises(BenchError) as err:
        from_json_lines(path)
    assert f"{path}:2:" in str(err.value) and why in str(err.value), str(err.value)


@pytest.mark.parametrize("x,shown", [(1 / 3, "0.333334"), (1000.0646, "1000.07"), (0.1 + 0.2, "0.3"), (2.0, "2"),
                                     (10.0646, "10.0646")])
def test_a_figure_is_rounded_up(x, shown):
    assert up(x) == shown and float(shown) >= x * (1 - 1e-12)


LIB = "actions:\n  stop: {plugin: log, level: warn, latch: true}\n  warn: {plugin: log, level: info}\n"
SPEC = """import "lib.yaml";
action primitive stop, warn;
entity e {
  rules:
    fast: (topic /a.data > 1) for 1 s;
    resumed: not active(stop);
    resumed_for: (not active(stop)) for 2 s;
    slow_age: 3 * age(topic /a) > 1 s;
    long: (topic /a.data > 0) for 1000 s;
}
if (e.fast) then { stop; }
if (e.resumed_for) then { warn; }
if (e.slow_age or e.long) then { warn; }
"""


def test_not_active_of_a_latched_action_has_no_time_by_design(write):
    write("lib.yaml", LIB)
    spec = check_text(SPEC, write("s.rbs", SPEC))
    for key in ("e.resumed", "e.resumed_for"):
        d = design(spec, ast.RuleRef(key))
        assert d.unknown and "latched" in d.unknown[0] and "~reset" in d.unknown[0], (key, d)
    assert design(spec, ast.RuleRef("e.fast")).chain == [1.0]


def test_the_page_rounds_its_totals_up(write, tmp_path, capsys):
    write("lib.yaml", LIB)
    path = write("s.rbs", SPEC)
    bench = _bench(write, dict(max=64.6, missed=0, extra=0))
    out = str(tmp_path / "r.html")
    main(["report", path, "--bench", bench, "-o", out])
    capsys.readouterr()
    html = open(out, encoding="utf-8").read()
    rows = {m.group(1): m.group(0) for m in re.finditer(r"<tr><td><code>(e\.\w+)</code>.*?</tr>", html, re.S)}
    assert "1000 s + ≤ 64.6 ms = ≤ 1000.07 s" in rows["e.long"], rows["e.long"]
    assert "0.333334 s + ≤ 64.6 ms = ≤ 0.397934 s" in rows["e.slow_age"], rows["e.slow_age"]
    assert "not computed" in rows["e.resumed"] and "latched" in rows["e.resumed"]


def test_a_reaction_case_without_its_figures_is_an_error_not_skipped(write):
    path = write("reaction.jsonl", CASE.format(max=7.25, missed=0, extra=0)
                 + '{"benchmark": "reaction", "rate_hz": 1000, "rubass": null, "rubass_unanswered": 0}\n')
    with pytest.raises(BenchError) as err:
        from_json_lines(path)
    assert f"{path}:2: a reaction case without its figures" in str(err.value)


def test_the_monitors_figures_are_rounded_up_on_the_page(write, tmp_path, capsys):
    write("lib.yaml", LIB)
    path = write("s.rbs", SPEC)
    out = str(tmp_path / "r.html")
    main(["report", path, "--bench", _bench(write, dict(max=1234.564, missed=0, extra=0)), "-o", out])
    capsys.readouterr()
    html = open(out, encoding="utf-8").read()
    assert "≤ 1234.57 ms" in html and "1234.56 ms" not in html


def test_an_output_that_is_a_folder_says_so(write, tmp_path, capsys):
    write("lib.yaml", LIB)
    path = write("s.rbs", SPEC)
    code = main(["report", path, "-o", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 1 and f"{tmp_path} is a folder: give the page's file name" in err and "Traceback" not in err


def test_a_test_file_that_cannot_run_is_named_on_the_last_line(write, tmp_path, capsys):
    write("lib.yaml", LIB)
    path = write("s.rbs", SPEC)
    broken = write("broken.test.yaml", "spec: s.rbs\ntests:\n  - name: x\n    topics: {}\n    expect: [{at: 1 s, strat: stop}]\n")
    code = main(["report", path, "--tests", broken, "-o", str(tmp_path / "r.html")])
    out = capsys.readouterr().out
    assert code == 1 and out.rstrip().splitlines()[-1].endswith(f"; not run: {broken}"), out


SMOKE = ('{"benchmark": "reaction", "rate_hz": 100, "background_load": false, "seconds": 0.5, "smoke": true, '
         '"rubass": {"n": 25, "p50_ms": 0.667, "p99_ms": 6.336, "max_ms": 6.336}, "rubass_unanswered": 0, '
         '"rubass_extra_stops": 0}\n')


def test_a_smoke_run_is_no_measurement(write):
    """A benchmark sweep: a 0.5 s, one-case --smoke run was stated as "the monitor's worst case"."""
    with pytest.raises(BenchError) as err:
        from_json_lines(write("reaction.jsonl", SMOKE))
    assert "reaction.jsonl:1: a --smoke run of bench/reaction.py" in str(err.value)
    assert "run it without --smoke" in str(err.value)


def test_the_page_says_what_the_benchmark_measured(write, tmp_path, capsys):
    """Rates, load, violations and seconds beside the figures: a short or unloaded measurement shows as one,
    and the command says when no case was under load."""
    lines = [SMOKE.replace('"smoke": true', '"smoke": false').replace('"background_load": false', f'"background_load": {b}')
             .replace('"rate_hz": 100', f'"rate_hz": {hz}').replace('"seconds": 0.5', '"seconds": 5')
             .replace('"n": 25', f'"n": {n}') for hz, b, n in ((100, "false", 500), (1000, "false", 2500),
                                                                  (100, "true", 500), (1000, "true", 2500))]
    r = from_json_lines(write("full.jsonl", "".join(lines)))
    assert r.extent == "at 100 Hz and 1000 Hz, 2 of 4 cases under background load, 6,000 violations in 20 s"
    write("lib.yaml", LIB)
    path = write("s.rbs", SPEC)
    out = str(tmp_path / "r.html")
    main(["report", path, "--bench", write("one.jsonl", lines[0]), "-o", out])
    err = capsys.readouterr().err
    assert "has no case under background load" in err, err
    html = open(out, encoding="utf-8").read()
    assert "at 100 Hz, no case under background load, 500 violations in 5 s" in html
