"""Two monitors on one robot publish /diagnostics statuses of different names.

Acceptance finding: `__name:=rb3` and `/rubass` both published `rubass: monitor` and `rubass: ENTITY`
(same hardware_id): a diagnostics aggregator merges statuses by name, so one monitor's OK could
mask the other's ERROR. A monitor not named /rubass says its node name."""
import pytest

from rosharness import spec

pytestmark = pytest.mark.ros


def test_a_second_monitor_names_its_statuses_by_its_node(ros, tmp_path):
    body = "entity base { rules: fast: topic /v.data > 1; }\nif (base.fast) then { stop; }\n"
    ros.monitor(spec(tmp_path, body))
    ros.monitor(spec(tmp_path, body, name="other.rbs"), name="rb3")
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"sleep": 2.5}]})
    names = {s["name"] for r in rec if r["kind"] == "recv" for s in r["msg"]["status"]}
    assert {"rubass: monitor", "rubass: base", "rubass /rb3: monitor", "rubass /rb3: base"} <= names, names
