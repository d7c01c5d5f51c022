"""`rubass replay` on bags the tests write with the rosbag API, and on a real recording."""
import json
import os
import subprocess
import sys

import pytest

rosbag = pytest.importorskip("rosbag")
import rospy  # noqa: E402
from geometry_msgs.msg import Twist  # noqa: E402
from std_msgs.msg import Float64, String  # noqa: E402

from conftest import ROOT, shared_path  # noqa: E402

pytestmark = pytest.mark.ros
LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")
T0 = 1700000000.0  # wall-clock-like stamps, as real bags have


def write_bag(path, items):
    """items: (seconds since T0, topic, message)."""
    with rosbag.Bag(path, "w") as bag:
        for t, topic, msg in items:
            bag.write(topic, msg, rospy.Time.from_sec(T0 + t))
    return path


def twist(x):
    m = Twist()
    m.linear.x = x
    return m


def spec_file(write, body):
    return write("s.rbs", f'import "{LIB}";\naction primitive stop, warn;\n' + body)


def replay(*args):
    proc = subprocess.run([sys.executable, "-m", "rubass", "replay", *args], cwd=ROOT, capture_output=True,
                          text=True, timeout=300)
    assert "Traceback" not in proc.stderr, proc.stderr
    return proc


SPEED = ("entity base { rules: fast: (topic /cmd_vel.linear.x > 1.0 m/s) for 0.5 s; }\n"
         "if (base.fast) then { stop; }\n")


def test_json_events_at_recorded_times(write, tmp_path):
    bag = write_bag(str(tmp_path / "b.bag"), [(0.0, "/cmd_vel", twist(0.2)), (1.0, "/cmd_vel", twist(1.5)),
                                              (1.2, "/cmd_vel", twist(1.6)), (3.0, "/cmd_vel", twist(0.0))])
    proc = replay(spec_file(write, SPEED), bag, "--json")
    assert proc.returncode == 0, proc.stderr
    lines = [json.loads(line) for line in proc.stdout.splitlines()]
    starts = [x for x in lines if x["event"] == "start"]
    assert len(starts) == 1 and starts[0]["time"] == pytest.approx(1.5, abs=1e-6)
    known = {k: starts[0][k] for k in ("time", "event", "behaviour", "line", "actions")}
    assert known == {"time": starts[0]["time"], "event": "start", "behaviour": 1, "line": 4, "actions": ["stop"]}
    # new fields only (docs/replay.md): why it started, at 1.5 s the message of 1.2 s
    assert starts[0]["rules"] == ["base.fast"] and starts[0]["witnesses"] == {"/cmd_vel.linear.x": 1.6}
    rule = [(x["time"], x["value"]) for x in lines if x["event"] == "rule"]
    assert [v for _, v in rule] == [None, False, True, False]
    assert [round(t, 6) for t, _ in rule] == [0.0, 0.0, 1.5, 3.0]
    assert [x["time"] for x in lines] == sorted(x["time"] for x in lines)
    assert not [x for x in lines if x["event"] == "release"]  # the stop is latched


def test_human_report_and_plot(write, tmp_path):
    bag = write_bag(str(tmp_path / "b.bag"), [(0.0, "/cmd_vel", twist(2.0)), (2.0, "/cmd_vel", twist(0.0))])
    png = tmp_path / "t.png"
    proc = replay(spec_file(write, SPEED.replace("stop;", "warn;")), bag, "--plot", str(png))
    assert proc.returncode == 0, proc.stderr
    assert "     0.500 s  start    behaviour 1 (line 4): warn" in proc.stdout
    assert "     2.000 s  release  behaviour 1 (line 4)" in proc.stdout
    assert "base.fast" in proc.stdout and "fired 1 time, active 1.500 s" in proc.stdout
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 5000


def test_ticks_fire_age_rules_between_messages(write, tmp_path):
    bag = write_bag(str(tmp_path / "b.bag"), [(0.0, "/odom", String("a")), (0.1, "/odom", String("b")),
                                              (5.0, "/other", String("end"))])
    spec = spec_file(write, "entity o { rules: silent: age(topic /odom) > 0.5 s; }\nif (o.silent) then { warn; }\n")
    proc = replay(spec, bag, "--json")
    starts = [json.loads(x) for x in proc.stdout.splitlines() if '"start"' in x]
    assert [round(s["time"], 5) for s in starts] == [0.6]


def test_missing_topic_is_a_warning_and_stays_unknown(write, tmp_path):
    bag = write_bag(str(tmp_path / "b.bag"), [(0.0, "/other", Float64(1.0))])
    proc = replay(spec_file(write, SPEED), bag, "--json")
    assert proc.returncode == 0
    assert (f"warning: topic /cmd_vel is not in {bag}; its fields stay unknown and its age() grows from the "
            "recording's start") in proc.stderr
    assert [json.loads(x)["value"] for x in proc.stdout.splitlines()] == [None]


def test_field_not_in_recorded_type_names_rule_field_and_type(write, tmp_path):
    bag = write_bag(str(tmp_path / "b.bag"), [(0.0, "/cmd_vel", twist(1.0))])
    spec = spec_file(write, "entity base { rules: fast: topic /cmd_vel.linear.q > 1; }\nif (base.fast) then { stop; }\n")
    proc = replay(spec, bag)
    assert proc.returncode == 1 and proc.stdout == ""
    # at its place, as `rubass check --bag` prints it (README: errors point at the place, all at once)
    assert [l for l in proc.stderr.splitlines() if ": error:" in l][0] == (  # warnings may come beside it
        f"{spec}:3:28: error: 'linear' (geometry_msgs/Vector3) has no field 'q' (its fields: x, y, z)")


def test_field_that_is_a_message_not_a_value(write, tmp_path):
    bag = write_bag(str(tmp_path / "b.bag"), [(0.0, "/cmd_vel", twist(1.0))])
    spec = spec_file(write, "entity base { rules: fast: topic /cmd_vel.linear > 1; }\nif (base.fast) then { stop; }\n")
    proc = replay(spec, bag)
    assert proc.returncode == 1
    first_error = next(l for l in proc.stderr.splitlines() if ": error:" in l)  # warnings may come beside it
    assert first_error.startswith(f"{spec}:3:28: error: 'topic /cmd_vel.linear' is a message, not a value: "
                                  "it is a geometry_msgs/Vector3"), proc.stderr


@pytest.mark.parametrize("content,expected", [
    (None, "no such file"),
    (b"not a bag at all\n" * 10, "not a readable ROS 1 bag"),
    (b"", "not a readable ROS 1 bag"),
])
def test_bad_bags_get_one_line_errors(write, tmp_path, content, expected):
    path = str(tmp_path / "x.bag")
    if content is not None:
        with open(path, "wb") as fh:
            fh.write(content)
    proc = replay(spec_file(write, SPEED), path)
    assert proc.returncode == 1
    assert proc.stderr.startswith("rubass replay: error: ") and expected in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_truncated_bag(write, tmp_path):
    bag = write_bag(str(tmp_path / "b.bag"), [(i * 0.01, "/cmd_vel", twist(1.0)) for i in range(2000)])
    data = open(bag, "rb").read()
    cut = str(tmp_path / "cut.bag")
    with open(cut, "wb") as fh:
        fh.write(data[: len(data) // 2])
    proc = replay(spec_file(write, SPEED), cut)
    assert proc.returncode == 1 and proc.stderr.startswith("rubass replay: error: ")
    assert "reindex" in proc.stderr or "not a readable" in proc.stderr or "corrupt" in proc.stderr


def test_bad_rate_is_a_usage_error(write, tmp_path):
    bag = write_bag(str(tmp_path / "b.bag"), [(0.0, "/cmd_vel", twist(1.0))])
    assert replay(spec_file(write, SPEED), bag, "--rate", "0").returncode == 2
    assert replay(spec_file(write, SPEED), bag, "--rate", "fast").returncode == 2


def test_real_turtlebot_recording():
    bag = shared_path("data", "turtlebot3_sim.bag")
    spec = os.path.join(ROOT, "test", "data", "turtlebot_gap.rbs")
    proc = replay(spec, bag, "--json")
    assert proc.returncode == 0, proc.stderr
    starts = [json.loads(x) for x in proc.stdout.splitlines() if '"start"' in x]
    # /cmd_vel has one gap over 3 s (4.061 s, from 13.000 s): the silence rule fires once, 3 s
    # into it, at the instant of the crossing rather than at the next tick
    silent = [s["time"] for s in starts if s["behaviour"] == 1]
    assert len(silent) == 1 and silent[0] == pytest.approx(16.0, abs=0.01)


@pytest.mark.parametrize("rule,words", [
    ("topic /data.data > 0", "is an array"),
    ("len(topic /name.data) > 3", "is not an array"),
    ("min(topic /name.data) > 3", "is not an array"),
])
def test_type_misuse_is_rejected_at_its_line(write, tmp_path, rule, words):  # issue 20.6
    from std_msgs.msg import Float64MultiArray

    arr = Float64MultiArray()
    arr.data = [1.0, 2.0]
    bag = write_bag(str(tmp_path / "b.bag"), [(0.0, "/data", arr), (0.0, "/name", String("abc"))])
    spec = spec_file(write, f"entity base {{ rules: r: {rule}; }}\nif (base.r) then {{ stop; }}\n")
    proc = replay(spec, bag)
    assert proc.returncode == 1 and proc.stdout == ""
    assert f"{spec}:3:" in proc.stderr and words in proc.stderr and "^" in proc.stderr, proc.stderr


def test_named_behaviours_are_named_in_starts_releases_and_the_summary(write, tmp_path):  # issue 12
    bag = write_bag(str(tmp_path / "b.bag"), [(0.0, "/cmd_vel", twist(2.0)), (2.0, "/cmd_vel", twist(0.0))])
    spec = spec_file(write, '@id("SR-1") entity base { rules: fast: topic /cmd_vel.linear.x > 1.0 m/s; }\n'
                            '@hazard("H1") overspeed: if (base.fast) then { warn; }\n')
    proc = replay(spec, bag)
    assert proc.returncode == 0, proc.stderr
    assert "     0.000 s  start    behaviour 1 overspeed (line 4): warn" in proc.stdout
    assert "@hazard: H1" in proc.stdout
    assert "     2.000 s  release  behaviour 1 overspeed (line 4)" in proc.stdout
    assert "  1. overspeed line 4 (warn): fired 1 time" in proc.stdout
    events = [json.loads(x) for x in replay(spec, bag, "--json").stdout.splitlines()]
    assert [(e["event"], e.get("name")) for e in events if e.get("event") in ("start", "release")] == \
        [("start", "overspeed"), ("release", "overspeed")]


def test_stamp_age_is_measured_against_the_recordings_own_time(write, tmp_path):
    """Header stamps are absolute: a replay from the bag's start must still see them as old or fresh."""
    from sensor_msgs.msg import Imu

    items = []
    for t, age in ((0.0, 0.0), (1.0, 0.0), (2.0, 1.0), (3.0, 0.0)):  # at 2 s the data is already 1 s old
        m = Imu()
        m.header.stamp = rospy.Time.from_sec(T0 + t - age)
        items.append((t, "/imu", m))
    bag = write_bag(str(tmp_path / "b.bag"), items)
    spec = spec_file(write, "entity d { rules: stale: stamp_age(topic /imu) > 0.5 s; }\n"
                            "stale_imu: if (d.stale) then { warn; }\n")
    proc = replay(spec, bag, "--json")
    assert proc.returncode == 0, proc.stderr
    events = [json.loads(x) for x in proc.stdout.splitlines()]
    got = [(e["event"], round(e["time"], 3)) for e in events if e.get("event") in ("start", "release")]
    # stale 0.5 s after each fresh stamp (the data ages between messages too), still stale with the
    # 1-second-old message at 2 s, fresh again at 3 s (the end of the recording)
    assert got == [("start", 0.5), ("release", 1.0), ("start", 1.5), ("release", 3.0)], got


def test_every_field_error_of_a_spec_is_reported_at_its_place(write, tmp_path):
    """Acceptance finding: replay stopped at the first wrong field, with no place."""
    from sensor_msgs.msg import LaserScan

    bag = write_bag(str(tmp_path / "b.bag"), [(0.0, "/cmd_vel", twist(1.0)), (0.1, "/scan", LaserScan())])
    spec = spec_file(write, "entity base { rules:\n  fast: topic /cmd_vel.linear.q > 0.3;\n"
                            "  arr: topic /scan.ranges > 1 m;\n}\nif (base.fast or base.arr) then { stop; }\n")
    proc = replay(spec, bag)
    assert proc.returncode == 1
    assert f"{spec}:4:9: error: 'linear' (geometry_msgs/Vector3) has no field 'q'" in proc.stderr, proc.stderr
    assert f"{spec}:5:8: error: 'topic /scan.ranges' is an array" in proc.stderr, proc.stderr


@pytest.mark.parametrize("plot,error", [
    ("x.txt", "argument --plot: cannot write a timeline as '.txt': use one of .png, .pdf, .svg, .jpg, .jpeg"),
    ("", "argument --plot: {tmp} is a folder: name the image file"),
])
def test_a_plot_file_that_cannot_be_written_is_refused_before_the_replay(write, tmp_path, plot, error):
    """Acceptance finding: '.txt' gave matplotlib's traceback after the whole replay."""
    bag = write_bag(str(tmp_path / "b.bag"), [(0.0, "/cmd_vel", twist(1.0))])
    proc = replay(spec_file(write, SPEED), bag, "--plot", str(tmp_path / plot) if plot else str(tmp_path))
    assert proc.returncode == 2 and proc.stdout == ""
    assert error.format(tmp=tmp_path) in proc.stderr, proc.stderr


def test_a_plot_name_without_a_format_is_written_as_png_and_named_so(write, tmp_path):
    bag = write_bag(str(tmp_path / "b.bag"), [(0.0, "/cmd_vel", twist(1.0))])
    proc = replay(spec_file(write, SPEED), bag, "--plot", str(tmp_path / "timeline"))
    assert proc.returncode == 0, proc.stderr
    assert f"timeline written to {tmp_path / 'timeline.png'}" in proc.stdout
    assert (tmp_path / "timeline.png").stat().st_size > 1000


def test_a_message_class_that_needs_ros_python_is_not_called_a_corrupt_bag(write, tmp_path, monkeypatch):
    """Acceptance finding: the python3 first on PATH (no genpy) got 'the bag is corrupt'."""
    from rubass.ros.bag import BagError, message_classes, open_bag

    bag_path = write_bag(str(tmp_path / "b.bag"), [(0.0, "/cmd_vel", twist(1.0))])

    def no_genpy(conn):
        raise ModuleNotFoundError("No module named 'genpy'")

    monkeypatch.setattr("rubass.ros.bagfile.message_class", no_genpy)
    bag, _ = open_bag(bag_path)
    with bag, pytest.raises(BagError) as info:
        message_classes(bag, ["/cmd_vel"])
    text = str(info.value)
    assert "corrupt" not in text and "needs ROS 1's Python message support" in text and "/usr/bin/python3" in text
