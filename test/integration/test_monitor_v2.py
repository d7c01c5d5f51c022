"""Language version 2 in the live monitor (issue 12): the same engine as replay, on real topics."""
import json

import pytest

from rosharness import TWIST, first, spec

pytestmark = pytest.mark.ros

SCAN = "sensor_msgs/LaserScan"


def scan(ranges):
    return {"range_min": 0.2, "range_max": 10.0, "ranges": ranges}


def test_a_laser_sector_stops_and_active_escalates_by_name(ros, tmp_path):
    ros.monitor(spec(tmp_path,
                     "entity field { rules: obstacle: min(topic /scan.ranges[0:3]) < 0.4 m; }\n"
                     "obstacle_stop: if (field.obstacle) then { stop; }\n"
                     "escalate: if (active(stop) for 0.3 s) then { brake; }\n"))
    rec = ros.probe({"listen": [{"topic": "/safety_cmd", "type": TWIST}, {"topic": "/brake", "type": "std_msgs/Bool"},
                                {"topic": "/rubass/events", "type": "std_msgs/String"}],
                     "advertise": [{"topic": "/scan", "type": SCAN}],
                     "steps": [{"wait_subscribers": "/scan"}, {"wait_publishers": "/safety_cmd"},
                               {"wait_publishers": "/brake"}, {"sleep": 0.3},
                               # no valid reading in the sector (NaN, no return, below range_min): unknown
                               {"publish": "/scan", "msg": scan([float("nan"), float("inf"), 0.1, 0.3])},
                               {"sleep": 0.5},
                               {"publish": "/scan", "msg": scan([0.35, float("inf"), 5.0, 9.0])},
                               {"wait": "/brake", "timeout": 5}]})
    sent = [r for r in rec if r["kind"] == "sent"]
    stop, brake = first(rec, "recv", "/safety_cmd"), first(rec, "recv", "/brake")
    assert stop is not None and brake is not None, rec
    assert stop["wall"] > sent[1]["wall"]  # not on the first scan: an empty sector is unknown, not an obstacle
    assert stop["wall"] - sent[1]["wall"] < 0.2
    assert brake["wall"] - stop["wall"] == pytest.approx(0.3, abs=0.08)  # active(stop) for 0.3 s
    events = [json.loads(r["msg"]["data"]) for r in rec if r["kind"] == "recv" and r["topic"] == "/rubass/events"]
    assert [(e["event"], e.get("name")) for e in events] == [("start", "obstacle_stop"), ("start", "escalate")]
    assert events[0]["witnesses"] == {"min(/scan.ranges[0:3])": pytest.approx(0.35)}  # float32 ranges


def test_stale_stamps_and_a_diagnostics_quantifier(ros, tmp_path):
    ros.monitor(spec(tmp_path,
                     "entity data { rules:\n"
                     "  stale: stamp_age(topic /imu) > 0.5 s;\n"
                     '  battery: any(topic /diag.status[*].name == "battery" and topic /diag.status[*].level >= 2);\n'
                     "}\n"
                     "if (data.stale) then { brake; }\n"
                     "if (data.battery) then { stop; }\n"))
    rec = ros.probe({"listen": [{"topic": "/safety_cmd", "type": TWIST}, {"topic": "/brake", "type": "std_msgs/Bool"}],
                     "advertise": [{"topic": "/imu", "type": "sensor_msgs/Imu"},
                                   {"topic": "/diag", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"wait_subscribers": "/imu"}, {"wait_subscribers": "/diag"},
                               {"wait_publishers": "/safety_cmd"}, {"wait_publishers": "/brake"}, {"sleep": 0.3},
                               {"publish": "/diag", "msg": {"status": [{"name": "battery", "level": 0},
                                                                       {"name": "motors", "level": 2}]}},
                               {"publish": "/imu", "msg": {"header": {"stamp": {"secs": 1, "nsecs": 0}}}},
                               {"wait": "/brake", "timeout": 5}, {"sleep": 0.3},
                               {"publish": "/diag", "msg": {"status": [{"name": "battery", "level": 2}]}},
                               {"wait": "/safety_cmd", "timeout": 5}]})
    sent = [r for r in rec if r["kind"] == "sent"]
    brake, stop = first(rec, "recv", "/brake"), first(rec, "recv", "/safety_cmd")
    assert brake is not None and stop is not None, rec
    assert brake["wall"] - sent[1]["wall"] < 0.2  # a stamp from 1970 is stale at once
    assert stop["wall"] > sent[2]["wall"]  # motors at level 2 is not the battery
