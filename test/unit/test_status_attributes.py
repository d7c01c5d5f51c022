"""§15: /diagnostics carries the attributes of rules and behaviours (found by an acceptance sweep:
`~events` had them, /diagnostics none, though docs/language.md says it carries them)."""
import os

import pytest

from rubass.actions import status
from rubass.lang import check_text

from conftest import ROOT

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")
SPEC = """action primitive warn;
@hazard("H1")
entity e {
  rules:
    @id("R-W") @title("w \\"high\\"") wh: topic /w.data > 1;
    low: topic /w.data < -1;
}
@id("B-W") @hazard("H1", "H2") bw: if (e.wh) then { warn; }
if (e.low) then { warn; }
"""


def entries(active):
    spec = check_text(SPEC, os.path.join(ROOT, "s.rbs"), [LIB])
    return status.build(spec, {"e.wh": True, "e.low": False}, active, {}, {}, {}, {})


def test_each_rule_entry_gives_its_attributes_beside_its_value():
    values = dict(entries([1])[0].values)
    assert values["wh attributes"] == '@hazard("H1") @id("R-W") @title("w \\"high\\"")'  # + its entity's hazard
    assert values["low attributes"] == '@hazard("H1")'  # its entity's (§15)


def test_active_behaviours_are_listed_with_their_names_and_attributes():
    values = dict(entries([1, 2])[-1].values)
    assert values["active behaviours"] == '1 (bw @id("B-W") @hazard("H1", "H2")), 2'


def test_the_last_start_names_the_behaviours_attributes():
    pytest.importorskip("rospy")  # the dispatcher's module reads the loop's message classes
    from rubass.actions.dispatch import Dispatcher
    from rubass.engine import Engine
    spec = check_text(SPEC, os.path.join(ROOT, "s.rbs"), [LIB])
    engine = Engine(spec, 0.0)
    engine.evaluate_all(0.0)
    d = Dispatcher({}, lambda record: None, lambda: 2.0)
    d.handle(engine, engine.on_message("/w", 1.0, {"data": 2.0}), "message")
    assert d.last_start.startswith('bw @id("B-W") @hazard("H1", "H2") at 1.000 s: true: e.wh')


def test_a_start_a_node_sample_caused_has_its_latency_from_the_samples_instant():
    """It was null, so `rubass experiments` could not split (b) of a run whose `for` ended with a sample
    (the CPU row, on a slower machine)."""
    pytest.importorskip("rospy")  # the dispatcher's module reads the loop's message classes
    from rubass.actions.dispatch import Dispatcher
    from rubass.engine import Engine
    from rubass.engine.loop import NodeSample

    spec = check_text("action primitive stop;\nentity e: n { rules: hot: cpu(node n) > 50 %; }\n"
                      "if (e.hot) then { stop; }\n", os.path.join(ROOT, "s.rbs"), [LIB])
    engine = Engine(spec, 0.0)
    engine.evaluate_all(0.0)
    records = []
    d = Dispatcher({}, records.append, lambda: 1.0045)
    sample = NodeSample("n", 1.0, True, 0.9, 1e6)
    d.handle(engine, engine.on_node_sample("n", 1.0, True, 0.9, 1e6), sample)
    (start,) = [r for r in records if r["event"] == "start"]
    assert start["cause"] == "node sample of n" and start["latency_ms"] == pytest.approx(4.5), start
