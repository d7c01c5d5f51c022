"""`failed action attempts` in /diagnostics is every failure since start (docs/monitor.md): a reload
that rebuilds an action (its definition changed) kept its runner's count, which started again at 0
(acceptance: 7 failures, then a rate edit and SIGHUP, then 0)."""
import time

import pytest
from rosharness import LIB, TWIST, spec, wait_log

pytestmark = pytest.mark.ros


def _monitor_values(ros):
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"wait": "/diagnostics", "timeout": 5}, {"sleep": 1.2}]})
    statuses = [s for r in rec if r["kind"] == "recv" for s in r["msg"]["status"] if s["name"] == "rubass: monitor"]
    return {kv["key"]: kv["value"] for kv in statuses[-1]["values"]}


def test_a_reload_that_rebuilds_an_action_keeps_the_record_of_its_failures(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { stop; }\n"))
    ros.probe({"advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],  # nobody listens to /safety_cmd
               "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.3}, {"publish": "/x", "msg": {"data": 5.0}},
                         {"sleep": 0.3}]})
    wait_log(mon, ros, "no node subscribes to /safety_cmd")
    time.sleep(1.0)
    before = int(_monitor_values(ros)["failed action attempts"])
    assert before >= 2
    listener = ros.probe_bg({"listen": [{"topic": "/safety_cmd", "type": TWIST}], "steps": [{"sleep": 30}]})
    time.sleep(2.0)  # the stop reaches its new subscriber: no more failures
    (tmp_path / "lib.yaml").write_text(LIB.replace("rate: 20 Hz, latch: true", "rate: 10 Hz, latch: true"))
    assert "reloaded" in ros.call("/rubass/reload").stdout
    after = int(_monitor_values(ros)["failed action attempts"])
    assert after >= before, (before, after)
    listener.kill()
