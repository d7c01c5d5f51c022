"""With use_sim_time true and no /clock message yet, the monitor enforces nothing (ROS time is 0):
it used to say so only in its log, and /diagnostics stayed silent, so a use_sim_time left set on a
real robot showed nothing. Now it publishes ERROR `NOT ENFORCING ANY RULE: use_sim_time is true and no
/clock message has come …` on the wall clock while it waits, and no ~heartbeat; once a /clock message
comes it enforces as before."""
import subprocess

import pytest
from rosharness import spec

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SPEC = "entity a { rules:\n  high: topic /x.data > 1;\n}\nif (a.high) then { warn; }\n"
DIAG = {"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}
BEAT = {"topic": "/rubass/heartbeat", "type": "std_msgs/Header"}


def _monitor_statuses(rec):
    return [s for r in rec if r["kind"] == "recv" and r["topic"] == "/diagnostics"
            for s in r["msg"]["status"] if s["name"] == "rubass: monitor"]


def test_waiting_for_the_first_clock_is_an_error_in_diagnostics_without_heartbeat(ros, tmp_path):
    subprocess.run(["rosparam", "set", "/use_sim_time", "true"], env=ros.env, check=True, timeout=20)
    mon = ros.monitor(spec(tmp_path, SPEC))
    rec = ros.probe({"listen": [DIAG, BEAT], "steps": [{"wait": "/diagnostics", "timeout": 10}, {"sleep": 2.5}]})
    statuses = _monitor_statuses(rec)
    assert len(statuses) >= 2, f"{rec}\n{ros.log(mon)}"  # at the diagnostics rate (1 Hz), not once
    s = statuses[-1]
    assert s["level"] == 2, s
    assert "NOT ENFORCING ANY RULE" in s["message"] and "use_sim_time is true" in s["message"], s
    assert "/clock" in s["message"], s
    values = {kv["key"]: kv["value"] for kv in s["values"]}
    assert values["use_sim_time"] == "true" and "heartbeat" in values, values
    assert not [r for r in rec if r["topic"] == "/rubass/heartbeat" and r["kind"] == "recv"], "a heartbeat while waiting"
    assert mon.poll() is None

    # the first /clock message: it enforces, the status says so, the heartbeat comes
    rec = ros.probe({"listen": [DIAG, BEAT], "advertise": [{"topic": "/clock", "type": "rosgraph_msgs/Clock"}],
                     "steps": [{"wait_subscribers": "/clock"}, {"sleep": 0.3}] + [
                         step for i in range(30) for step in (
                             {"publish": "/clock", "msg": {"clock": {"secs": 50 + i // 10, "nsecs": (i % 10) * 100000000}}},
                             {"sleep": 0.1})]})
    statuses = _monitor_statuses(rec)
    assert statuses and statuses[-1]["message"].startswith("enforcing"), f"{statuses}\n{ros.log(mon)}"
    assert [r for r in rec if r["topic"] == "/rubass/heartbeat" and r["kind"] == "recv"], ros.log(mon)
