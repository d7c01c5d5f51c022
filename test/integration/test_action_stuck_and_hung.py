"""The acceptance repros of a live monitor: a custom plugin whose start never returns is reported
(log, /diagnostics ACTION FAILING) while the other actions go on; a service that never answers,
called on start and every hold, no longer leaves one thread per attempt in the monitor."""
import os
import signal
import time

import pytest

from rosharness import LIB, TWIST, spec, wait_log

pytestmark = [pytest.mark.ros, pytest.mark.slow]


def x_high(ros, seconds):
    """A background publisher that makes `a.r` true and keeps its connection for `seconds`."""
    return ros.probe_bg({"advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
                         "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.2}, {"publish": "/x", "msg": {"data": 5.0}},
                                   {"sleep": seconds}]}, name="x")


def monitor_status(ros):
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"sleep": 2.5}]})
    return [s for r in rec if r["kind"] == "recv" for s in r["msg"]["status"] if s["name"] == "rubass: monitor"][-1]


def threads(proc):
    with open(f"/proc/{proc.pid}/status") as f:
        return next(int(line.split()[1]) for line in f if line.startswith("Threads:"))


def test_a_custom_plugin_whose_start_hangs_is_reported_stuck_and_the_stop_goes_on(ros, tmp_path):
    (tmp_path / "plug").mkdir()
    (tmp_path / "plug" / "badplug.py").write_text(
        "import time\n"
        "class Hang:\n"
        "    def __init__(self, name, params):\n"
        "        pass\n"
        "    def start(self, ctx):\n"
        "        time.sleep(1e5)\n"
        "    def hold(self, ctx):\n"
        "        pass\n"
        "    def release(self, ctx):\n"
        "        pass\n")
    ros.env["PYTHONPATH"] = str(tmp_path / "plug") + os.pathsep + ros.env["PYTHONPATH"]
    lib = LIB + "  hang: {plugin: 'badplug:Hang'}\n"
    path = spec(tmp_path, "action primitive hang;\nentity a { rules: r: topic /x.data > 1; }\n"
                          "if (a.r) then { hang; stop; }\n", lib=lib)
    mon = ros.monitor(path)
    x_high(ros, 30)
    stops = ros.probe({"listen": [{"topic": "/safety_cmd", "type": TWIST}], "steps": [{"sleep": 1.5}]})
    assert [r for r in stops if r["kind"] == "recv"], "the stop is not held up by the stuck action"
    wait_log(mon, ros, "action 'hang' start has not returned for", timeout=10)
    assert "the action is stuck" in ros.log(mon)
    status = monitor_status(ros)
    assert status["level"] in (2, b"\x02"), status
    assert "ACTION FAILING" in status["message"] and "hang: start has not returned for" in status["message"], status
    assert ros.log(mon).count("action 'hang' start has not returned for") <= 2, "logged once, then every 5 s"
    mon.send_signal(signal.SIGTERM)  # the stuck thread does not hold the monitor up at exit
    assert mon.wait(10) == 0, ros.log(mon)


def test_a_service_that_never_answers_leaves_at_most_one_call_behind(ros, tmp_path):
    lib = LIB + ("  brake_srv: {plugin: service, service: /brake_srv, type: std_srvs/Trigger, timeout: 0.3 s, "
                 "call_on: [start, hold]}\n")
    path = spec(tmp_path, "action primitive brake_srv;\nentity a { rules: r: topic /x.data > 1; }\n"
                          "if (a.r) then { brake_srv; stop; }\n", lib=lib)
    mon = ros.monitor(path)
    ros.probe_bg({"serve": [{"service": "/brake_srv", "type": "std_srvs/Trigger", "delay": 1000}],
                  "steps": [{"sleep": 60}]}, name="server")
    ros.wait_service("/brake_srv")
    x_high(ros, 60)
    wait_log(mon, ros, "did not answer within 0.3 s", timeout=10)
    time.sleep(1.0)
    before = threads(mon)
    time.sleep(6.0)  # one thread per attempt grew this by 6 or more (18 -> 56 in 50 s live)
    after = threads(mon)
    assert after - before <= 2, (before, after)
    status = monitor_status(ros)
    assert status["level"] in (2, b"\x02") and "brake_srv" in status["message"], status
    wait_log(mon, ros, "the previous call to /brake_srv has not returned after", timeout=10)
