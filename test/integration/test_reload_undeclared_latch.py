"""docs/monitor.md, Live reload: a reload whose spec no longer declares a latched, active action
that its library still defines is accepted, and the latched stop goes on until ~reset (it is
rejected only when no loaded library defines the action any more: test_reliability_latch.py)."""
import time

import pytest
from rosharness import LIB, spec
from test_reliability_latch import BODY, stops_within, trigger_and_clear

pytestmark = [pytest.mark.ros, pytest.mark.slow]


def test_a_spec_that_stops_declaring_a_latched_active_action_reloads_and_the_stop_goes_on(ros, tmp_path):
    spec(tmp_path, BODY)
    ros.monitor(str(tmp_path / "s.rbs"))
    trigger_and_clear(ros)
    assert (tmp_path / "lib.yaml").read_text() == LIB  # the library still defines stop
    (tmp_path / "s.rbs").write_text('import "lib.yaml";\naction primitive warn;\n'
                                    "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { warn; }\n")
    time.sleep(0.1)
    out = ros.call("/rubass/reload")
    assert "reloaded" in out.stdout, out.stdout
    assert len(stops_within(ros, 1.0)) >= 10, "the latched stop goes on after the reload"
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"sleep": 2.5}]})
    mon = [s for r in rec if r["kind"] == "recv" for s in r["msg"]["status"] if s["name"] == "rubass: monitor"]
    assert mon and mon[-1]["level"] >= 1 and "HOLDING until ~reset: stop (behaviour 1" in \
        mon[-1]["message"], mon[-1:]  # the robot is held: /diagnostics says by what (it said OK, none active)
    out = ros.call("/rubass/reset")
    assert "released 1 latched behaviour" in out.stdout, out.stdout
    assert len(stops_within(ros, 1.0)) == 0, "~reset ends it"
