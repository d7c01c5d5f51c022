"""Every start explains itself: the true rules and the values they read, at the transition only."""
import json
import os
import time

from rubass.engine import Engine
from rubass.engine.explain import Witness, label
from rubass.lang import ast, check_text

from conftest import ROOT

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")

SPEC = """action primitive stop, warn;
entity base: controller {
  rules:
    too_fast: topic /odom.twist.twist.linear.x > 0.5 m/s;
    silent: age(topic /cmd_vel) > 0.5 s;
    hot: cpu(node controller) > 90 %;
    close: min(topic /scan.ranges) < 0.4 m;
    unused: topic /odom.pose.pose.position.x > 100;
}
if (base.too_fast or base.unused) then { stop; }
if (base.silent) then { warn; }
if (base.hot and base.close) then { stop; }
"""


def engine():
    e = Engine(check_text(SPEC, os.path.join(ROOT, "x.rbs"), [LIB]), 0.0)
    e.evaluate_all(0.0)
    return e


def odom(vx, x=0.0):
    return {"twist": {"twist": {"linear": {"x": vx}}}, "pose": {"pose": {"position": {"x": x}}}}


def test_start_carries_true_rules_and_field_values():
    e = engine()
    events = e.on_message("/odom", 0.3, odom(0.62))
    (start,) = [ev for ev in events if ev.kind == "start"]
    w = start.witness
    assert w.rules == ("base.too_fast",)  # base.unused is false: not a cause
    assert w.values()["/odom.twist.twist.linear.x"] == 0.62
    assert "/odom.pose.pose.position.x" not in w.values()  # read only by a false rule: not a cause


def test_a_rule_read_under_not_is_a_cause_when_false_with_the_values_it_reads():
    """`if (not pos.in_cell)` started with no rule and no value (acceptance sweep): the rule's being
    false is the cause; a double `not` reads it as it is."""
    spec = check_text("action primitive stop, warn;\nentity e { rules:\n  p: topic /a.data > 0;\n"
                      "  q: topic /b.data > 0;\n  n: not p;\n}\nif (not e.p) then { stop; }\n"
                      "if (e.n and not not e.q) then { warn; }\n", os.path.join(ROOT, "x.rbs"), [LIB])
    e = Engine(spec, 0.0)
    e.evaluate_all(0.0)
    e.on_message("/b", 0.1, {"data": 2.0})
    starts = {ev.behaviour: ev.witness for ev in e.on_message("/a", 0.2, {"data": -1.0}) if ev.kind == "start"}
    assert (starts[1].rules, starts[1].false_rules) == ((), ("e.p",))
    assert starts[1].values() == {"/a.data": -1.0} and starts[1].as_json()["false_rules"] == ["e.p"]
    assert starts[1].causes() == "false: e.p"
    assert (set(starts[2].rules), starts[2].false_rules) == ({"e.n", "e.q"}, ("e.p",))
    assert starts[2].values() == {"/b.data": 2.0, "/a.data": -1.0}
    assert "false_rules" not in Witness(("e.q",), ()).as_json()  # the JSON of every other start is as it was


def test_age_witness_has_its_unit_and_the_deadline_value():
    e = engine()
    e.on_message("/cmd_vel", 0.2, None)
    events = e.advance(2.0)
    (start,) = [ev for ev in events if ev.kind == "start"]
    assert start.behaviour == 2 and start.witness.rules == ("base.silent",)
    age = start.witness.values()["age(/cmd_vel)"]
    assert 0.5 < age < 0.5001  # the instant of the crossing, not a later tick
    assert start.witness.units()["age(/cmd_vel)"] == "s"
    assert "age(/cmd_vel) = 0.5" in start.witness.readings[0].text()


def test_node_and_array_functions_are_read_but_not_whole_arrays():
    e = engine()
    e.on_node_sample("controller", 0.1, True, 0.95, 1e6)
    events = e.on_message("/scan", 0.2, {"ranges": [1.0, 0.3, 2.0]})
    (start,) = [ev for ev in events if ev.kind == "start"]
    vals = start.witness.values()
    assert vals == {"cpu(controller)": 0.95, "min(/scan.ranges)": 0.3}
    assert start.witness.units()["cpu(controller)"] == "cores"
    assert json.dumps(start.witness.as_json())  # JSON-ready


def test_releases_and_rule_events_carry_no_witness():
    e = engine()
    events = e.on_message("/odom", 0.1, odom(0.62)) + e.on_message("/odom", 0.2, odom(0.0))
    assert [ev.kind for ev in events if ev.witness is not None] == ["start"]


def test_labels():
    assert label(ast.TopicRef("/scan", ("ranges", 0))) == "/scan.ranges[0]"
    assert label(ast.Frequency("/odom", 2.0)) == "frequency(/odom, 2 s)"
    assert label(ast.Age("/cmd_vel")) == "age(/cmd_vel)"
    assert label(ast.ArrayFn("min", ast.TopicRef("/scan", ("ranges", ast.Slice(0, 90))))) == "min(/scan.ranges[0:90])"
    assert label(ast.Call("min", (ast.Lit(1.0), ast.Lit(2.0)))) is None  # arithmetic: its operands are read


def test_witnesses_cost_nothing_on_the_message_path():
    """Messages that start nothing never build a witness: same speed with explain disabled."""
    e = engine()
    calls = []
    real = e.explain
    e.explain = lambda i: calls.append(i) or real(i)
    for k in range(2000):
        e.on_messages(k * 1e-4, [("/odom", odom(0.1)), ("/cmd_vel", None)])
    assert calls == []
    e.on_messages(0.3, [("/odom", odom(0.9)), ("/cmd_vel", None)])
    assert calls == [1]


def test_explain_is_cheap_at_the_transition():
    e = engine()
    e.on_message("/odom", 1.0, odom(0.62))
    t0 = time.perf_counter()
    for _ in range(200):
        e.explain(1)
    assert (time.perf_counter() - t0) / 200 < 0.005  # generous on a loaded machine


def test_replay_json_and_report_show_witnesses():
    import io

    from rubass.replay import report

    e = engine()
    events = e.on_message("/odom", 0.3, odom(0.62))
    out = io.StringIO()
    report.json_lines(events, out)
    (line,) = [json.loads(x) for x in out.getvalue().splitlines() if '"start"' in x]
    assert line["witnesses"] == {"/odom.twist.twist.linear.x": 0.62} and line["rules"] == ["base.too_fast"]
    text = io.StringIO()
    report.human(e.spec, events, 1.0, text)
    assert "true: base.too_fast" in text.getvalue()
    assert "/odom.twist.twist.linear.x = 0.62" in text.getvalue()


def test_monitor_events_and_diagnostics_carry_the_witness():
    from rubass.actions.dispatch import Dispatcher

    records = []
    d = Dispatcher({}, records.append, lambda: 0.3)
    e = engine()
    d.handle(e, e.on_message("/odom", 0.3, odom(0.62)), "deadline")
    (rec,) = records
    assert rec["event"] == "start" and rec["witnesses"] == {"/odom.twist.twist.linear.x": 0.62}
    assert rec["rules"] == ["base.too_fast"]
    assert d.last_start == "behaviour 1 at 0.300 s: true: base.too_fast; /odom.twist.twist.linear.x = 0.62"


def test_witness_benchmark_runs_and_finds_no_call_on_the_message_path():
    import subprocess
    import sys

    out = subprocess.run([sys.executable, os.path.join(ROOT, "bench", "witness.py"), "--messages", "200"],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    figures = json.loads(out.stdout)
    assert figures["explain_calls_on_the_message_path"] == 0 and figures["one_witness_us"] > 0


QSPEC = """action primitive stop;
const CELL = polygon((0 m, 0 m), (1 m, 0 m), (1 m, 1 m));
entity b { rules:
  close: count(topic /scan.ranges[*] < 0.4 m) > 1;
  near: any(topic /scan.ranges[0:2] <  /* tight */ 0.4 m);
  edge: distance(topic /odom.pose.pose.position.x, topic /odom.pose.pose.position.y, CELL) < 0.2 m;
}
if (b.close) then { stop; }
if (b.near) then { stop; }
if (b.edge) then { stop; }
"""


def qengine():
    e = Engine(check_text(QSPEC, os.path.join(ROOT, "q.rbs"), [LIB]), 0.0)
    e.evaluate_all(0.0)
    return e


def test_quantifiers_are_witnessed_with_their_value_as_written():
    e = qengine()
    events = e.on_message("/scan", 0.1, {"ranges": [0.1, 0.2, 0.3, 0.35, 1.0]})
    starts = {ev.behaviour: ev.witness for ev in events if ev.kind == "start"}
    assert starts[1].values() == {"count(/scan.ranges[*] < 0.4 m)": 4}
    assert type(starts[1].values()["count(/scan.ranges[*] < 0.4 m)"]) is int  # a count, as JSON shows it
    assert starts[2].values() == {"any(/scan.ranges[0:2] < 0.4 m)": True}  # the comment left out
    assert "count(/scan.ranges[*] < 0.4 m) = 4" in [r.text() for r in starts[1].readings]
    assert json.dumps(starts[1].as_json())


def test_distance_is_witnessed_besides_its_x_and_y():
    e = qengine()
    events = e.on_message("/odom", 0.1, {"pose": {"pose": {"position": {"x": 0.9, "y": 0.1}}}})
    (start,) = [ev for ev in events if ev.kind == "start"]
    vals = start.witness.values()
    assert abs(vals["distance(/odom.pose.pose.position.x, /odom.pose.pose.position.y, CELL)"] - 0.1) < 1e-9
    assert vals["/odom.pose.pose.position.x"] == 0.9 and vals["/odom.pose.pose.position.y"] == 0.1
    assert start.witness.units()["distance(/odom.pose.pose.position.x, /odom.pose.pose.position.y, CELL)"] == "m"


def test_quantifier_and_zone_labels_without_sources():
    q = ast.Quant("count", ast.TopicRef("/scan", ("ranges",)), ast.Lit(True))
    assert label(q) == "count(/scan.ranges[*] …)"
    z = ast.Zone("inside", ast.TopicRef("/p", ("x",)), ast.TopicRef("/p", ("y",)), ())
    assert label(z) == "inside(/p.x, /p.y, …)"
