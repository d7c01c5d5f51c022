"""docs/failure-modes.md, action holders: a reload whose action library turns `latch: true` into
`latch: false` while that latched stop is held is rejected (it would release the protective stop
without ~reset, where a restart keeps holding it); after ~reset the same reload is accepted."""
import json
import os
import signal
import time

import pytest
from rosharness import LIB, spec, wait_log
from test_reliability_latch import BODY, stops_within, trigger_and_clear

pytestmark = [pytest.mark.ros, pytest.mark.slow]

UNLATCHED = LIB.replace("rate: 20 Hz, latch: true", "rate: 20 Hz, latch: false")


def test_a_reload_that_unlatches_a_held_stop_is_rejected_and_the_stop_goes_on_until_reset(ros, tmp_path):
    assert UNLATCHED != LIB
    path = spec(tmp_path, BODY)
    mon = ros.monitor(path)
    trigger_and_clear(ros)  # the cause is gone: only the latch holds the stop
    events = ros.probe_bg({"listen": [{"topic": "/rubass/events", "type": "std_msgs/String"}],
                           "steps": [{"wait_publishers": "/rubass/events"}, {"sleep": 0.5}, {"mark": "listening"},
                                     {"sleep": 4.0}]}, name="events")
    assert '"listening"' in events.stdout.readline()
    (tmp_path / "lib.yaml").write_text(UNLATCHED)
    time.sleep(0.1)
    os.kill(mon.pid, signal.SIGHUP)  # as the tester did
    wait_log(mon, ros, "reload (SIGHUP) rejected")
    assert "makes stop not latched (latch: false) while it is latched and active" in ros.log(mon), ros.log(mon)
    assert "call ~reset first" in ros.log(mon)
    assert len(stops_within(ros, 1.0)) >= 10, f"the latched stop goes on:\n{ros.log(mon)}"
    out, _ = events.communicate(timeout=30)
    released = [json.loads(r["msg"]["data"]) for r in map(json.loads, out.splitlines())
                if r.get("kind") == "recv" and '"release"' in r["msg"]["data"]]
    assert released == [], released  # no release with cause "reload"
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"wait": "/diagnostics", "timeout": 5}, {"sleep": 1.2}]})
    mon_status = [s for r in rec if r["kind"] == "recv" for s in r["msg"]["status"] if s["name"] == "rubass: monitor"]
    assert mon_status and mon_status[-1]["level"] == 2, mon_status[-1:]  # ERROR: the reload was rejected
    assert "the last reload was rejected" in mon_status[-1]["message"], mon_status[-1]

    out = ros.call("/rubass/reset")
    assert "released 1 latched behaviour" in out.stdout, out.stdout
    out = ros.call("/rubass/reload")  # nothing is held now: the library may drop the latch
    assert "reloaded" in out.stdout, out.stdout
    assert stops_within(ros, 1.0) == []
