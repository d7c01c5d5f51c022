"""A unit error only the live types reveal (`linear.x > 3 s` on a Twist: `rubass check` without a
model accepts it, `check --bag`/`--live` and replay reject it): the monitor logs it once at its
place, /diagnostics shows it as an ERROR of the monitor, and the rule still stops the robot on the
numbers as written; a reload that fixes the unit clears it."""
import pytest

from rosharness import brake_after, spec, wait_log

pytestmark = pytest.mark.ros

BODY = "entity base {{ rules: fast: topic /cmd_vel.linear.x > 3 {unit}; }}\nif (base.fast) then {{ brake; }}\n"


def _monitor_status(ros):
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"sleep": 2.5}]})
    return [s for r in rec if r["kind"] == "recv" for s in r["msg"]["status"] if s["name"] == "rubass: monitor"]


def test_a_unit_error_the_live_types_reveal_is_logged_shown_and_the_rule_still_stops(ros, tmp_path):
    path = spec(tmp_path, BODY.format(unit="s"))
    mon = ros.monitor(path)
    assert brake_after(ros, 4.0)  # 4 m/s > 3 (s): evaluated on the numbers, as before
    wait_log(mon, ros, "the spec does not fit the message types its topics carry")
    assert "s.rbs:3:52: error: compares a speed with a time" in ros.log(mon), ros.log(mon)
    statuses = _monitor_status(ros)
    assert statuses and statuses[-1]["level"] == 2, statuses  # ERROR
    assert "SPEC ERROR against the live message types" in statuses[-1]["message"], statuses[-1]
    assert ros.log(mon).count("does not fit the message types") == 1  # once, not at every status

    spec(tmp_path, BODY.format(unit="m/s"))
    assert "true" in ros.call("/rubass/reload").stdout.lower()
    assert brake_after(ros, 4.0)
    statuses = _monitor_status(ros)
    assert statuses and statuses[-1]["level"] == 0, statuses  # the fixed spec: OK again
    assert "SPEC ERROR" not in statuses[-1]["message"]


def test_a_spec_that_fits_the_live_types_says_nothing(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, BODY.format(unit="m/s")))
    assert brake_after(ros, 4.0)
    statuses = _monitor_status(ros)
    assert statuses and "SPEC ERROR" not in statuses[-1]["message"], statuses
    assert "does not fit the message types" not in ros.log(mon)
