"""Every start explains itself on a live system: ~events and /diagnostics carry the witness."""
import json

import pytest

from rosharness import spec

pytestmark = pytest.mark.ros


def test_events_and_diagnostics_carry_the_witness(ros, tmp_path):
    ros.monitor(spec(tmp_path, '@hazard("H1") entity a { rules: @id("SR-1") r: topic /x.data > 1; }\n'
                               '@id("SF-1") fast: if (a.r) then { brake; }\n'))
    rec = ros.probe({"listen": [{"topic": "/rubass/events", "type": "std_msgs/String"},
                                {"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
                     "steps": [{"wait_subscribers": "/x"}, {"wait_publishers": "/rubass/events"}, {"sleep": 0.3},
                               {"publish": "/x", "msg": {"data": 5.0}}, {"sleep": 1.5}]})
    events = [json.loads(r["msg"]["data"]) for r in rec if r.get("topic") == "/rubass/events"]
    start = next(e for e in events if e["event"] == "start")
    assert start["name"] == "fast" and start["attrs"] == {"id": ["SF-1"]}
    assert start["rules"] == ["a.r"] and start["witnesses"] == {"/x.data": 5.0}
    diags = [r["msg"] for r in rec if r.get("topic") == "/diagnostics"]
    values = [v for d in diags for s in d["status"] if s["name"] == "rubass: monitor" for v in s["values"]
              if v["key"] == "last start"]
    assert values and values[-1]["value"].startswith('fast @id("SF-1") at ')
    assert "true: a.r; /x.data = 5" in values[-1]["value"]
