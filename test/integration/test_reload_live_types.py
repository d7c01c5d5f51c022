"""A reload is checked against the message types the spec's topics carry at that moment, as
`rubass check --live` would: a typo in a field path of a live topic (`linear.xx`) would read
unknown from the swap on and release an active stop, so the reload is rejected at its place and
the running rules keep braking (found by an acceptance sweep: it was accepted, the stop released,
and the error logged a second later)."""
import pytest

from rosharness import brake_after, spec

pytestmark = pytest.mark.ros

BODY = "entity base {{ rules: fast: topic /cmd_vel.linear.{field} > 3 m/s; }}\nif (base.fast) then {{ brake; }}\n"


def _brakes(ros, seconds):
    rec = ros.probe({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}], "steps": [{"sleep": seconds}]})
    return [r for r in rec if r["kind"] == "recv" and r["msg"]["data"] is True]


def test_a_reload_with_a_field_the_live_type_lacks_is_rejected_and_the_active_brake_goes_on(ros, tmp_path):
    mon = ros.monitor(spec(tmp_path, BODY.format(field="x")))
    assert brake_after(ros, 4.0)  # the brake is on, and /cmd_vel is known to carry a Twist

    spec(tmp_path, BODY.format(field="xx"))
    out = ros.call("/rubass/reload").stdout
    assert "rejected, the previous rules keep running" in out, out
    log = ros.log(mon)
    assert "does not fit the message types its topics carry now" in log, log
    assert "s.rbs:3:28: error: 'linear' (geometry_msgs/Vector3) has no field 'xx'; did you mean 'x'?" in log, log
    assert len(_brakes(ros, 1.0)) >= 10, ros.log(mon)  # 20 Hz: still braking, not released
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"sleep": 2.5}]})
    shown = [v["value"] for r in rec if r["kind"] == "recv" for st in r["msg"]["status"]
             if st["name"] == "rubass: monitor" for v in st["values"] if v["key"] == "last reload error"]
    assert shown and "has no field 'xx'" in shown[-1], shown  # the error itself, not a heading

    spec(tmp_path, BODY.format(field="x") + "if (base.fast) then { warn; }\n")
    assert "true" in ros.call("/rubass/reload").stdout.lower(), ros.log(mon)  # a spec that fits is taken
    assert len(_brakes(ros, 1.0)) >= 10, ros.log(mon)
