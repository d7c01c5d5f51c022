"""Incremental evaluation (issue 17): after a message the engine skips a node that reads no
changed field and no node that changed value, unless it is volatile (time, node samples,
active()) or one of its operators (for, within, latch) is at its deadline. Checked against the
same engine evaluating every node of the plan, on random input."""
import os
import random

from rubass.engine import Engine
from rubass.lang import check_text

from conftest import ROOT

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")

SPEC = """action primitive stop, warn;
entity r: /p; { rules:
  a: topic /x.v > 1;
  b: topic /y.v < 0 or a;
  c: (topic /x.v > 2) for 0.2 s;
  d: b and not c;
  e: max(topic /s.r[0:3]) > 1;
  f: any(topic /s.r[*] > 2) and topic /y.v == 0;
  g: age(topic /y) > 0.3 s;
  h: latch(topic /x.v > 2.5, topic /y.v < -1);
  i: (topic /x.v + topic /y.v > 1) within 0.3 s;
  j: active(warn) and topic /y.v > 0;
  k: topic /x.w == "on";
  n: cpu(node /p) > 0.5 and topic /y.v > 0;
  m: n or a;
}
if (r.d or r.e) then { warn; }
if (r.j or r.g) then { stop; }
if (r.f and r.k) then { stop; }
if (r.m and not r.d) then { warn; }
"""


class FullEngine(Engine):
    """The same engine, evaluating every node of every plan."""

    def _run(self, plan, events, changed=None):
        super()._run(plan, events, None)


def _feed(engine, seq):
    out = []
    for t, topic, msg in seq:
        if topic is None:
            out += engine.on_tick(t)
        elif topic == "node":
            out += engine.on_node_sample("/p", t, True, msg)
        else:
            out += engine.on_message(topic, t, msg)
    return [(e.time, e.kind, e.behaviour, e.rule, e.value) for e in out]


def _assert_same_as_full_evaluation(spec, seq):
    inc, full = Engine(spec, 0.0), FullEngine(spec, 0.0)
    assert _feed(inc, [(0.0, None, None)] + seq) == _feed(full, [(0.0, None, None)] + seq)
    assert inc.store.rules == full.store.rules
    assert inc.active_behaviours() == full.active_behaviours()


def test_incremental_evaluation_gives_the_events_of_full_evaluation():
    rnd = random.Random(17)
    spec = check_text(SPEC, os.path.join(ROOT, "x.rbs"), [LIB])
    for _ in range(30):
        t, seq = 0.0, []
        for _ in range(300):
            t += rnd.choice([0.0, 0.01, 0.05, 0.1, 0.25])
            kind = rnd.random()
            if kind < 0.35:  # few distinct values: messages often repeat what the last one said
                seq.append((t, "/x", {"v": rnd.choice([0, 1.5, 2.2, 3, float("nan")]), "w": rnd.choice(["on", "off"])}))
            elif kind < 0.7:
                seq.append((t, "/y", {"v": rnd.choice([-2, -0.5, 0, 0.5])}))
            elif kind < 0.8:
                seq.append((t, "node", rnd.choice([0.2, 0.7])))
            elif kind < 0.9:
                seq.append((t, "/s", {"r": tuple(rnd.choice([0.5, 1.5, 3.0]) for _ in range(rnd.choice([2, 4])))}))
            else:
                seq.append((t, None, None))
        _assert_same_as_full_evaluation(spec, seq)


def test_a_message_that_changes_nothing_skips_its_nodes_until_an_operators_deadline():
    spec = check_text(SPEC, os.path.join(ROOT, "x.rbs"), [LIB])
    engine = Engine(spec, 0.0)
    engine.evaluate_all(0.0)
    engine.on_message("/x", 0.1, {"v": 3, "w": "on"})
    calls = []
    for node in engine._nodes:
        fn = node.compiled.fn
        node.compiled.fn = (lambda key, fn: lambda: calls.append(key) or fn())(node.key, fn)
    engine.on_message("/x", 0.2, {"v": 3, "w": "on"})  # the same values again
    assert "r.a" not in calls and "r.b" not in calls and "r.k" not in calls  # pure, inputs unchanged
    # for, latch, within with the same operand give the same value until their deadline
    assert "r.c" not in calls and "r.h" not in calls and "r.i" not in calls
    events = engine.advance(0.31)  # c = (x.v > 2) for 0.2 s, true since 0.1: its deadline, 0.3
    assert "r.c" in calls and [(round(e.time, 9), e.rule, e.value) for e in events if e.rule == "r.c"] == \
        [(0.3, "r.c", True)]
    engine.on_message("/x", 0.35, {"v": 0, "w": "on"})
    assert "r.a" in calls and "r.b" in calls  # a changed, so b (which reads a) is evaluated too


STATEFUL = """action primitive stop, warn;
entity r { rules:
  a: topic /x.v > 1;
  b: topic /y.v < 0;
  c: (a and not b) for 0.2 s;
  d: b within 0.15 s;
  e: latch(a, b);
  f: (c or d) for 0.1 s;
}
if (r.a for 0.3 s) then { warn; }
if (r.c or (r.d within 0.1 s)) then { stop; }
if (latch(r.b, r.a) and r.f) then { warn; }
"""


def test_operators_over_rules_and_in_behaviours_give_the_events_of_full_evaluation():
    # instants on a 0.05 s grid: deadlines (0.1, 0.15, 0.2, 0.3 s) often fall on a message's instant
    rnd = random.Random(23)
    spec = check_text(STATEFUL, os.path.join(ROOT, "x.rbs"), [LIB])
    for _ in range(40):
        t, seq = 0.0, []
        for _ in range(200):
            t = round(t + rnd.choice([0.0, 0.05, 0.05, 0.1, 0.15]), 2)
            kind = rnd.random()
            if kind < 0.45:
                seq.append((t, "/x", {"v": rnd.choice([0, 2, 2, 2, float("nan")])}))
            elif kind < 0.9:
                seq.append((t, "/y", {"v": rnd.choice([-1, 1, 1, 1])}))
            else:
                seq.append((t, None, None))
        _assert_same_as_full_evaluation(spec, seq)
