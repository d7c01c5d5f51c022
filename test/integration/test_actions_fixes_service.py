"""Acceptance fixes of the `service` action on a live monitor: a hung service does not block the
action once a reload points it at a working one; `success: false` is a failure (logged, retried,
ERROR); a service the master does not know fails at once, and a release that called nothing does
not show that failure resolved in /diagnostics."""
import time

import pytest

from rosharness import LIB, PY, spec, wait_log

pytestmark = [pytest.mark.ros, pytest.mark.slow]

SERVER = '''#!/usr/bin/python3
import time
import rospy
from std_srvs.srv import Trigger, TriggerResponse
rospy.init_node("svcs", disable_signals=True)
def brake(req):
    print("brake called", flush=True)
    return TriggerResponse(True, "ok")
def hang(req):
    print("hang called", flush=True)
    end = time.time() + 60
    while time.time() < end and not rospy.is_shutdown():
        time.sleep(0.05)
    return TriggerResponse(True, "late")
def fail(req):
    print("fail called", flush=True)
    return TriggerResponse(False, "refused")
for name, handler in (("/brake", brake), ("/hang", hang), ("/failsvc", fail)):
    rospy.Service(name, Trigger, handler)
print("ready", flush=True)
import signal
signal.signal(signal.SIGTERM, lambda *a: rospy.signal_shutdown("term"))
while not rospy.is_shutdown():
    time.sleep(0.05)
'''


def server(ros, tmp_path):
    (tmp_path / "svcs.py").write_text(SERVER)
    proc = ros.spawn([PY, str(tmp_path / "svcs.py")], "svcs")
    ros.wait_service("/failsvc", proc)
    return proc


def set_x(ros, value):
    return ros.probe({"advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
                      "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.2}, {"mark": "sent"},
                                {"publish": "/x", "msg": {"data": value}}, {"sleep": 0.1}]})


def monitor_status(ros):
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"sleep": 2.5}]})
    return [s for r in rec if r["kind"] == "recv" for s in r["msg"]["status"] if s["name"] == "rubass: monitor"][-1]


def action_lib(body):
    return LIB + body


def test_a_reload_away_from_a_hung_service_calls_the_new_one(ros, tmp_path):
    srv = server(ros, tmp_path)
    lib = "  brk: {plugin: service, service: /hang, type: std_srvs/Trigger, timeout: 0.3 s}\n"
    path = spec(tmp_path, "action primitive brk;\nentity a { rules: r: topic /x.data > 1; }\nif (a.r) then { brk; }\n",
                lib=action_lib(lib))
    mon = ros.monitor(path)
    set_x(ros, 5.0)
    wait_log(mon, ros, "service /hang did not answer within 0.3 s", timeout=10)
    set_x(ros, 0.0)
    (tmp_path / "lib.yaml").write_text(action_lib(lib.replace("/hang", "/brake")))
    out = ros.call("/rubass/reload")
    assert out.returncode == 0 and "True" in out.stdout, out.stdout + out.stderr
    set_x(ros, 5.0)
    wait_log(srv, ros, "brake called", timeout=10)
    assert "the previous call to /brake" not in ros.log(mon)
    assert ros.log(srv).count("hang called") == 1


def test_a_service_that_answers_success_false_is_a_failure_retried_and_shown(ros, tmp_path):
    srv = server(ros, tmp_path)
    lib = "  fail_s: {plugin: service, service: /failsvc, type: std_srvs/Trigger}\n"
    path = spec(tmp_path, "action primitive fail_s;\nentity a { rules: r: topic /x.data > 1; }\n"
                          "if (a.r) then { fail_s; }\n", lib=action_lib(lib))
    mon = ros.monitor(path)
    set_x(ros, 5.0)
    wait_log(mon, ros, "service /failsvc answered success: false: 'refused'", timeout=10)
    end = time.time() + 10
    while ros.log(srv).count("fail called") < 3 and time.time() < end:
        time.sleep(0.05)
    assert ros.log(srv).count("fail called") >= 3, "retried (0.05, 0.1, 0.2 s …)"
    status = monitor_status(ros)
    assert status["level"] in (2, b"\x02"), status
    assert "ACTION FAILING: fail_s: start: ServiceRefused: service /failsvc answered success: false" \
        in status["message"], status


def test_an_unknown_service_fails_at_once_and_a_release_that_called_nothing_does_not_resolve_it(ros, tmp_path):
    lib = "  brake2: {plugin: service, service: /nobrake, type: std_srvs/Trigger, timeout: 6 s}\n"
    path = spec(tmp_path, "action primitive brake2;\nentity a { rules: r: topic /x.data > 1; }\n"
                          "if (a.r) then { brake2; }\n", lib=action_lib(lib))
    mon = ros.monitor(path)
    rec = set_x(ros, 5.0)
    sent = next(r["wall"] for r in rec if r["kind"] == "mark")
    wait_log(mon, ros, "service /nobrake does not exist (not advertised on the master)", timeout=10)
    assert time.time() - sent < 4.0, "at once, not after its 6 s timeout"
    set_x(ros, 0.0)  # the release: call_on is [start], so it calls nothing
    time.sleep(0.5)
    status = monitor_status(ros)
    values = {v["key"]: v["value"] for v in status["values"]}
    assert status["level"] in (2, b"\x02"), status
    assert "ACTION FAILING: brake2: start:" in status["message"] and "does not exist" in status["message"], status
    assert "released before an attempt succeeded" in status["message"], status
    assert not values.get("action brake2", "").startswith("resolved"), values
