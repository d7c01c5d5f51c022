"""Acceptance fix: a `publish` stop of a stamped type (a top-level std_msgs/Header) goes out with the
current ROS time in header.stamp, each publication, as the limit's zero commands do; a stamp the
library sets itself is kept. It went out stamped 0 (dropped as stale by a node checking its age)."""
import pytest

from rosharness import LIB, spec

pytestmark = [pytest.mark.ros, pytest.mark.slow]

STAMPED = "geometry_msgs/TwistStamped"


def sec(stamp):
    """The probe's record of a time: {secs, nsecs} (or seconds)."""
    return stamp["secs"] + stamp["nsecs"] * 1e-9 if isinstance(stamp, dict) else stamp


def test_a_stamped_publish_stop_carries_the_current_time_unless_the_library_sets_it(ros, tmp_path):
    lib = LIB + (f"  sstop: {{plugin: publish, topic: /sstop, type: {STAMPED}, message: {{}}, rate: 20 Hz}}\n"
                 f"  fixed: {{plugin: publish, topic: /fixed, type: {STAMPED}, rate: 20 Hz,\n"
                 f"          message: {{header: {{stamp: {{secs: 7, nsecs: 0}}, frame_id: base}}}}}}\n")
    path = spec(tmp_path, "action primitive sstop, fixed;\nentity a { rules: r: topic /x.data > 1; }\n"
                          "if (a.r) then { sstop; fixed; }\n", lib=lib)
    ros.monitor(path)
    rec = ros.probe({"listen": [{"topic": "/sstop", "type": STAMPED}, {"topic": "/fixed", "type": STAMPED}],
                     "advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
                     "steps": [{"wait_subscribers": "/x"}, {"wait_publishers": "/sstop"}, {"sleep": 0.5},
                               {"publish": "/x", "msg": {"data": 5.0}}, {"sleep": 1.0}]})
    got = [r for r in rec if r["kind"] == "recv" and r["topic"] == "/sstop"]
    assert len(got) >= 10, got
    stamps = [sec(r["msg"]["header"]["stamp"]) for r in got]
    assert all(abs(s - r["wall"]) < 2.0 for s, r in zip(stamps, got)), stamps[:3]  # now, not 0 (1970)
    assert len(set(stamps)) == len(stamps), "each publication stamped anew"
    assert all(r["msg"]["twist"]["linear"]["x"] == 0.0 for r in got)
    fixed = [r["msg"]["header"] for r in rec if r["kind"] == "recv" and r["topic"] == "/fixed"]
    assert fixed and all(sec(h["stamp"]) == 7.0 and h["frame_id"] == "base" for h in fixed), fixed[:3]
