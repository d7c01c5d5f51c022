"""A dead sensor beside a publisher of another type on its topic: the other type's messages cannot
be read (no field the spec reads is in them), so they are no data and the `age` guard still stops
the robot (acceptance: a std_msgs/Float32 on /scan kept age(/scan) fresh and the laser's death hidden)."""
import pytest

from rosharness import first, spec

pytestmark = pytest.mark.ros

BODY = ("entity laser { rules: near: topic /x.data < 0.5; stale: age(topic /x) > 0.5 s; }\n"
        "if (laser.near or laser.stale) then { brake; }\n")


def test_another_types_messages_do_not_keep_a_dead_sensor_fresh(ros, tmp_path):
    ros.monitor(spec(tmp_path, BODY))
    ros.probe({"advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],  # the sensor, then it dies
               "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.3}, {"publish": "/x", "msg": {"data": 3.0}},
                         {"sleep": 0.1}]})
    steps = [{"wait_subscribers": "/x"}, {"mark": "go"}]
    for _ in range(15):  # 1.5 s of another type at 10 Hz
        steps += [{"publish": "/x", "msg": {"data": "not a range"}}, {"sleep": 0.1}]
    rec = ros.probe({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}],
                     "advertise": [{"topic": "/x", "type": "std_msgs/String"}], "steps": steps})
    go = next(r["wall"] for r in rec if r["kind"] == "mark")
    brake = first([r for r in rec if r["kind"] != "recv" or r["wall"] > go], "recv", "/brake")
    assert brake is not None, "the strings kept age(/x) fresh: the dead sensor was never stale"
