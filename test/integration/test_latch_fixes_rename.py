"""docs/failure-modes.md, latch state file: a restart after renaming a latched, active stop (the
state file names an action the spec no longer declares) cannot run that stop, so the monitor
withholds its ~heartbeat (a watchdog fed by it keeps the robot stopped), says so in /diagnostics
(ERROR) and the log, keeps the latch in the file across another restart, until ~reset."""
import json
import os
import signal
import time

import pytest
from rosharness import LIB, spec, wait_log
from test_reliability_latch import BODY, trigger_and_clear

pytestmark = [pytest.mark.ros, pytest.mark.slow]

HB = "/rubass/heartbeat"


def beats_and_status(ros, seconds=1.5):
    """The heartbeats received in `seconds`, and the monitor's last /diagnostics status."""
    rec = ros.probe({"listen": [{"topic": HB, "type": "std_msgs/Header"},
                                {"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"wait": "/diagnostics", "timeout": 5}, {"sleep": seconds}]})
    beats = [r for r in rec if r["kind"] == "recv" and r["topic"] == HB]
    mon = [s for r in rec if r["kind"] == "recv" and r["topic"] == "/diagnostics" for s in r["msg"]["status"]
           if s["name"] == "rubass: monitor"]
    return beats, mon[-1]


def kill9(mon):
    os.killpg(mon.pid, signal.SIGKILL)
    mon.wait(10)


def test_a_restart_after_renaming_a_latched_stop_withholds_the_heartbeat_until_reset(ros, tmp_path):
    path = spec(tmp_path, BODY)
    mon = ros.monitor(path)
    beats, _ = beats_and_status(ros, 0.5)
    assert beats, "a monitor that enforces beats"
    trigger_and_clear(ros)
    kill9(mon)
    (tmp_path / "lib.yaml").write_text(LIB.replace("  stop:", "  halt:"))
    (tmp_path / "s.rbs").write_text('import "lib.yaml";\naction primitive halt, brake, warn;\n'
                                    + BODY.replace("stop", "halt"))
    state = tmp_path / "ros_home" / "rubass" / f"rubass.{ros.port}.latches.json"
    for attempt in range(2):  # a second restart before ~reset still knows of the latch
        mon = ros.monitor(path)
        wait_log(mon, ros, "NO ~heartbeat until ~reset")
        beats, status = beats_and_status(ros)
        assert beats == [], f"restart {attempt + 1}: no heartbeat while the latched stop cannot be held:\n{ros.log(mon)}"
        assert status["level"] == 2 and "NO ~heartbeat until ~reset" in status["message"] \
            and "stop (behaviour 1" in status["message"], status
        assert "stop" in json.dumps(json.loads(state.read_text())["latched"]), "kept in the file until ~reset"
        if attempt == 0:
            kill9(mon)
    out = ros.call("/rubass/reset")
    assert "released 1 latched behaviour" in out.stdout, out.stdout
    time.sleep(0.3)
    beats, status = beats_and_status(ros)
    assert len(beats) >= 10 and status["level"] == 0, (len(beats), status)
    assert json.loads(state.read_text())["latched"] == []
    assert mon.poll() is None
