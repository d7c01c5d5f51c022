"""Live: /diagnostics says why a rule is unknown when its data came but the expression makes unknown
of it (division by zero, an index past the end, min of an empty array, sqrt of a negative number):
the acceptance tester found these with no `… unknown because` value at all."""
import pytest
from rosharness import spec

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SPEC = """entity a { rules:
  ratio: topic /a.data / topic /b.data > 2;
  fifth: topic /arr.data[5] > 1;
  least: min(topic /arr2.data) > 1;
  root: sqrt(topic /b2.data) > 1;
}
if (a.ratio or a.fifth or a.least or a.root) then { warn; }
"""
F64, ARR = "std_msgs/Float64", "std_msgs/Float64MultiArray"


def test_computed_unknowns_have_a_reason_in_diagnostics(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, SPEC))
    pubs = [("/a", F64, {"data": 1e200}), ("/b", F64, {"data": 0.0}), ("/arr", ARR, {"data": [1.0, 2.0]}),
            ("/arr2", ARR, {"data": []}), ("/b2", F64, {"data": -4.0})]
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "advertise": [{"topic": t, "type": ty} for t, ty, _ in pubs],
                     "steps": [{"wait_subscribers": t} for t, _, _ in pubs] + [{"sleep": 0.3}]
                     + [{"publish": t, "msg": m} for t, _, m in pubs] + [{"sleep": 2.5}]})
    entity = [s for r in rec if r["kind"] == "recv" for s in r["msg"]["status"] if s["name"] == "rubass: a"]
    assert entity, ros.log(mon)
    values = {kv["key"]: kv["value"] for kv in entity[-1]["values"]}
    for rule in ("ratio", "fifth", "least", "root"):
        assert values[rule] == "unknown", values
    assert "division by zero" in values["ratio unknown because"], values
    assert "1e+200 / 0" in values["ratio unknown because"], values
    assert "index out of range" in values["fifth unknown because"], values
    assert "empty array" in values["least unknown because"], values
    assert "sqrt of a negative number" in values["root unknown because"], values
    assert entity[-1]["level"] == 0, entity[-1]  # unknown is not a data error
