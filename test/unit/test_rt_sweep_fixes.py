"""Rule tests and `rubass report`: defects an acceptance sweep found, each pinned down.

A dead node's test sample kept its last cpu (a test passed that the live monitor would fail); the
matrix called a hazard covered while a rule its behaviour uses had an uncovered @id; `--bench` took a
max below its p99 as the worst case; `%` was read as seconds, 1/s and bytes; an empty hazard title read
"must be a text, not a text"; one expectation's tolerance let the whole test see past its end; a lone
surrogate in a test name crashed; `header: {stamp: 500 ms}` was refused; `~x` under `topics:` became
`/~x`; `0x1.5` read "'x1.5' is not a unit".
"""
import re

from rubass.cli import main

LIB = """actions:
  stop: {plugin: log, level: warn}
  warn: {plugin: log, level: warn}
"""

NODE_SPEC = """import "lib.yaml";
action primitive stop;
entity base: controller { rules:
  @id("SR-CPU") overloaded: (cpu(node controller) > 90 %) for 1 s;
  @id("SR-MEM") big: memory(node controller) > 40 MB;
}
overload: if (base.overloaded) then { stop; }
big: if (base.big) then { stop; }
"""

SPEC = """import "lib.yaml";
action primitive stop, warn;
entity base { rules:
  recent: (topic /bump.data) within 1 s;
  stale: stamp_age(topic /scan) > 0.3 s;
  quiet: age(topic /cmd_vel) > 0.5 s;
  p: topic ~lim.data > 1;
}
r: if (base.recent) then { stop; }
q: if (base.quiet) then { warn("quiet"); }
s: if (base.stale) then { warn("stale"); }
pp: if (base.p) then { warn("p"); }
"""


def _setup(write, spec=SPEC):
    write("lib.yaml", LIB)
    write("s.rbs", spec)


def _test(write, capsys, tests, spec=SPEC):
    _setup(write, spec)
    path = write("s.test.yaml", "spec: s.rbs\ntests:\n" + tests)
    code = main(["test", path])
    out, err = capsys.readouterr()
    return code, out, err, path


def _line(path, text):
    with open(path, encoding="utf-8") as fh:
        return next(n for n, line in enumerate(fh, 1) if text in line)


# -- 1. a node that is not alive has no cpu or memory ------------------------------------------

def test_a_dead_node_does_not_keep_its_last_cpu(write, capsys):
    code, out, err, _ = _test(write, capsys, """  - name: dies while hot
    duration: 3 s
    nodes:
      controller:
        - {at: 0 s, alive: true, cpu: 95 %, memory: 50 MB}
        - {at: 0.5 s, alive: false}
    expect:
      - {at: 1 s, start: overload}
""", NODE_SPEC)
    assert code == 1, out + err  # as live: the monitor reads cpu unknown once the node is dead
    assert "FAIL  dies while hot" in out and "no start or release" in out


def test_a_node_alive_again_is_measured_afresh(write, capsys):
    code, out, err, _ = _test(write, capsys, """  - name: restarts
    duration: 3 s
    nodes:
      controller:
        - {at: 0 s, alive: true, memory: 50 MB}
        - {at: 1 s, alive: false}
        - {at: 2 s, alive: true}
    expect:
      - {at: 0 s, start: big}
      - {at: 1 s, release: big}
""", NODE_SPEC)
    assert code == 0, out + err  # memory unknown at 2 s: not carried over the death


def test_cpu_on_a_sample_of_a_dead_or_unknown_node_is_an_error(write, capsys):
    code, out, err, path = _test(write, capsys, """  - name: dead but measured
    duration: 3 s
    nodes:
      controller:
        - {at: 0 s, alive: false, cpu: 95 %}
        - {at: 1 s, alive: null, memory: 50 MB}
        - {at: 2 s, alive: true, cpu: 95 %}
    expect:
      - {never: overload}
""", NODE_SPEC)
    assert code == 2, out + err
    assert f"{path}:{_line(path, 'alive: false, cpu')}: error: a node that is not alive has no cpu: the " \
           f"monitor reads it unknown" in err
    assert f"{path}:{_line(path, 'alive: null')}: error: a node that is not known to be alive has no memory" in err
    assert "Traceback" not in err


# -- 2. the matrix: a rule a row rests on with an @id no test covers is a gap --------------------

MX_SPEC = """import "lib.yaml";
action primitive stop, warn;
entity base { rules:
  @id("R-PLAIN") plain: topic /a.data > 1;
  @id("R-HELP") commanded: topic /c.data > 0.1;
  @id("R-MAIN") @hazard("H4") stuck: base.commanded and topic /v.data < 0.01;
}
@id("B-1") @hazard("H3") act: if (base.plain) then { stop; }
halt: if (base.stuck) then { warn("x"); }
"""
MX_TESTS = """spec: s.rbs
tests:
  - name: act stops on plain
    covers: [B-1, H3]
    duration: 2 s
    topics:
      /a: {type: std_msgs/Float64, messages: [{at: 0.5 s, data: 2}]}
    expect:
      - {at: 0.5 s, start: act}
  - name: stuck
    covers: [R-MAIN, H4]
    duration: 2 s
    topics:
      /c: {type: std_msgs/Float64, messages: [{at: 0.5 s, data: 1}]}
      /v: {type: std_msgs/Float64, messages: [{at: 0.5 s, data: 0}]}
    expect:
      - {at: 0.5 s, start: halt}
"""


def test_a_row_is_a_gap_while_a_rule_it_uses_is_uncovered(write, capsys, tmp_path):
    _setup(write, MX_SPEC)
    tests = write("s.test.yaml", MX_TESTS)
    hz = write("hz.yaml", "hazards:\n  - {id: H3, title: Three}\n  - {id: H4, title: Four}\n")
    page = str(tmp_path / "r.html")
    code = main(["report", str(tmp_path / "s.rbs"), "--tests", tests, "--hazards", hz, "-o", page])
    out, err = capsys.readouterr()
    assert code == 0, out + err
    assert "2 tests passed, 0 failed, 2 gaps in the matrix" in out  # H3's behaviour row and H4's rule row
    text = open(page, encoding="utf-8").read()
    gaps = re.findall(r"<td class='gap'>(.*?)</td>", text)
    assert any("no test covers R-PLAIN (rule base.plain, used here)" in g for g in gaps), gaps
    assert any("no test covers R-HELP (rule base.commanded, used here)" in g for g in gaps), gaps


def test_covering_the_used_rules_clears_the_gaps(write, capsys, tmp_path):
    _setup(write, MX_SPEC)
    tests = write("s.test.yaml", MX_TESTS.replace("[B-1, H3]", "[B-1, H3, R-PLAIN]")
                  .replace("[R-MAIN, H4]", "[R-MAIN, H4, R-HELP]"))
    hz = write("hz.yaml", "hazards:\n  - {id: H3, title: Three}\n  - {id: H4, title: Four}\n")
    code = main(["report", str(tmp_path / "s.rbs"), "--tests", tests, "--hazards", hz, "-o",
                 str(tmp_path / "r.html")])
    out, err = capsys.readouterr()
    assert code == 0 and "0 gaps in the matrix" in out, out + err


# -- 3. bench figures out of order bound nothing ------------------------------------------------

def test_bench_figures_out_of_order_are_an_error_at_their_line(write, capsys, tmp_path):
    _setup(write, NODE_SPEC)
    good = '{"benchmark": "reaction", "rubass": {"p50_ms": 1, "p99_ms": 2, "max_ms": 3}}\n'
    for bad in ('{"benchmark": "reaction", "rubass": {"p50_ms": 4, "p99_ms": 9, "max_ms": 1}}',
                '{"benchmark": "reaction", "rubass": {"p50_ms": 5, "p99_ms": 2, "max_ms": 6}}'):
        bench = write("b.jsonl", good + bad + "\n")
        code = main(["report", str(tmp_path / "s.rbs"), "--bench", bench, "-o", str(tmp_path / "r.html")])
        out, err = capsys.readouterr()
        assert code == 1, out + err
        assert f"{bench}:2: the figures are out of order" in err and "no upper bound" in err
    bench = write("b.jsonl", good)
    assert main(["report", str(tmp_path / "s.rbs"), "--bench", bench, "-o", str(tmp_path / "r.html")]) == 0


# -- 4. a share is no time, rate or size ---------------------------------------------------------

def test_percent_is_no_time_rate_or_memory(write, capsys):
    code, out, err, path = _test(write, capsys, """  - name: shares
    duration: 300 %
    tolerance: 10 %
    topics:
      /bump: {type: std_msgs/Bool, rate: 100 %, field: data, values: "truex3"}
      /cmd_vel: {type: geometry_msgs/Twist, rate: 10 Hz, start: 5 %, field: linear.x, values: "0x3"}
    expect:
      - {at: 50 %, start: r}
  - name: memory share
    duration: 2 s
    nodes:
      controller:
        - {at: 0.5 s, alive: true, memory: 50 %}
    expect:
      - {never: r}
""")
    assert code == 2, out + err
    for field, value, unit in (("duration", "300 %", "seconds"), ("tolerance", "10 %", "seconds"),
                               ("rate", "100 %", "Hz"), ("start", "5 %", "seconds"), ("at", "50 %", "seconds"),
                               ("memory", "50 %", "bytes")):
        line = _line(path, f"{field}: {value}")
        assert f"{path}:{line}: error: {field}: '{value}' is a share, not a quantity in {unit}" in err, err


def test_a_bare_number_still_takes_the_default_unit(write, capsys):
    code, out, err, _ = _test(write, capsys, """  - name: bare
    duration: "2"
    tolerance: "0.001"
    topics:
      /bump: {type: std_msgs/Bool, messages: [{at: "0.5", data: true}]}
    expect:
      - {at: 0.5, start: r}
""")
    assert code == 0, out + err


# -- 5. an empty hazard title ------------------------------------------------------------------

def test_an_empty_title_is_said_to_be_empty(write, capsys, tmp_path):
    _setup(write)
    hz = write("hz.yaml", 'hazards:\n  - id: H1\n    title: "  "\n    plr: ""\n')
    code = main(["report", str(tmp_path / "s.rbs"), "--hazards", hz, "-o", str(tmp_path / "r.html")])
    out, err = capsys.readouterr()
    assert code == 1
    assert f"{hz}:3:12: error: hazard 1: the title must be a text, not an empty text" in err, err
    assert f"{hz}:4:10: error: hazard 1: 'plr' must be a plain value shown beside the hazard, not an empty text" in err


# -- 6. nothing after the end, but within an expectation's own window ----------------------------

def test_one_tolerance_does_not_let_the_whole_test_see_past_its_end(write, capsys):
    code, out, err, _ = _test(write, capsys, """  - name: release after the end
    duration: 2 s
    topics:
      /bump: {type: std_msgs/Bool, messages: [{at: 0.5 s, data: true}, {at: 1.5 s, data: false}]}
    expect:
      - {at: 0.5 s, start: r}
      - {at: 0.5 s, start: q, tolerance: 600 ms}
  - name: never sees past the end
    duration: 2 s
    topics:
      /cmd_vel: {type: geometry_msgs/Twist, rate: 10 Hz, field: linear.x, values: "0x18"}
    expect:
      - {at: 0.5 s, start: r, tolerance: 1 s}
      - {never: q}
""")
    assert code == 1, out + err  # r never starts in the second: that fails, and only that
    assert "PASS  release after the end" in out
    assert "q: expected never" not in out and "r (line" in out


def test_an_expectation_whose_window_reaches_past_the_end_sees_it(write, capsys):
    code, out, err, _ = _test(write, capsys, """  - name: a start just after the end, within its window
    duration: 2 s
    topics:
      /cmd_vel: {type: geometry_msgs/Twist, messages: [{at: 1.6 s, linear: {x: 0}}]}
    expect:
      - {at: 0.5 s, start: q}
      - {at: 1.6 s, release: q}
      - {at: 2 s, start: q, tolerance: 200 ms}
""")
    assert code == 0, out + err


# -- 7. a lone surrogate --------------------------------------------------------------------------

def test_a_lone_surrogate_is_an_error_at_its_line(write, capsys, tmp_path):
    code, out, err, path = _test(write, capsys, """  - name: "lone \\uD800"
    duration: 1 s
    expect:
      - {at: 0.5 s, start: q}
""")
    assert code == 2 and "Traceback" not in err
    assert f"{path}:{_line(path, 'lone')}: error: a text holds a lone surrogate" in err
    code = main(["report", str(tmp_path / "s.rbs"), "--tests", path, "-o", str(tmp_path / "r.html")])
    out, err = capsys.readouterr()
    assert "Traceback" not in err and "a text holds a lone surrogate" in err
    hz = write("hz.yaml", 'hazards:\n  - {id: H1, title: "bad \\uD800"}\n  - {id: H2, title: "ok \\uD83D\\uDE00"}\n')
    code = main(["report", str(tmp_path / "s.rbs"), "--hazards", hz, "-o", str(tmp_path / "r.html")])
    out, err = capsys.readouterr()
    assert code == 1 and f"{hz}:2:21: error: a text holds a lone surrogate" in err and "3:" not in err, err


def test_an_escaped_pair_is_its_character(write, capsys):
    code, out, err, _ = _test(write, capsys, """  - name: "smile \\uD83D\\uDE00"
    duration: 1 s
    expect:
      - {at: 0.5 s, start: q}
""")
    assert code == 0, out + err
    assert "smile \U0001F600" in out


# -- 8. a stamp with a unit ---------------------------------------------------------------------

def test_a_header_stamp_takes_units(write, capsys):
    code, out, err, _ = _test(write, capsys, """  - name: stamp forms
    duration: 2 s
    topics:
      /scan:
        type: sensor_msgs/LaserScan
        messages:
          - {at: 0.5 s, header: {stamp: 500 ms}}
          - {at: 1.0 s, header.stamp: "950 ms"}
    expect:
      - {at: 0.8 s, start: s}
      - {at: 1.0 s, release: s}
      - {at: 1.25 s, start: s}
""")
    assert code == 0, out + err


# -- 9. `~x` under topics, a count that is no whole number ------------------------------------

def test_a_private_topic_in_a_test_is_the_monitors(write, capsys):
    code, out, err, _ = _test(write, capsys, """  - name: tilde
    duration: 2 s
    topics:
      ~lim: {type: std_msgs/Float64, messages: [{at: 0.5 s, data: 2}]}
    expect:
      - {at: 0.5 s, start: pp}
""")
    assert code == 0, out + err
    assert "warning" not in err


def test_a_repeat_count_must_be_whole(write, capsys):
    code, out, err, path = _test(write, capsys, """  - name: count
    duration: 1 s
    topics:
      /bump: {type: std_msgs/Bool, rate: 10 Hz, field: data, values: "truex1.5"}
    expect:
      - {never: r}
""")
    assert code == 2
    assert f"{path}:{_line(path, 'truex1.5')}: error: values of data: 'truex1.5': N in xN (how many times) must " \
           f"be a whole number of at least 1, not 1.5" in err, err
