"""One topic written several ways in a spec (`/x`, `x`, `~x`) is one topic in `rubass test` and
`rubass replay`, as in the live monitor (docs/monitor.md): every spelling gets every message, and
`~x` resolves in the monitor's default node namespace, `/rubass/x`."""
import json

import pytest

from rubass.cli import main
from rubass.lang.topicnames import resolve, spellings

LIB = "actions:\n  warn: {plugin: log, level: warn}\n"
SPEC = """import "lib.yaml";
action primitive warn;
entity e {
  rules:
    abs_: topic /x.data > 1;
    rel_: topic x.data > 1;
    priv_: topic ~p.data > 1;
    priv_age: age(topic ~p) > 10 s;
}
on_abs: if (e.abs_) then { warn; }
on_rel: if (e.rel_) then { warn; }
on_priv: if (e.priv_) then { warn; }
"""


@pytest.mark.parametrize("name,resolved", [("x", "/x"), ("/x", "/x"), ("~x", "/rubass/x"), ("~/x", "/rubass/x"),
                                           ("a/b", "/a/b"), ("~x/y", "/rubass/x/y"), ("x/", "/x")])
def test_names_resolve_as_rospy_resolves_them_in_the_default_monitor(name, resolved):
    assert resolve(name) == resolved
    rosgraph_names = pytest.importorskip("rosgraph.names")
    assert rosgraph_names.resolve_name(name, "/rubass") == resolved


def test_spellings_group_the_names_of_one_topic():
    assert spellings(["x", "/x", "~x", "/y"]) == {"/x": ["/x", "x"], "/rubass/x": ["~x"], "/y": ["/y"]}


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_rule_tests_feed_every_spelling_of_a_topic(write, capsys):
    write("lib.yaml", LIB)
    write("robot.rbs", SPEC)
    path = write("t.test.yaml", """spec: robot.rbs
tests:
  - name: one topic, two spellings; a private one
    duration: 2 s
    topics:
      /x: {type: std_msgs/Float64, messages: [{at: 0.5 s, data: 2}]}
      /rubass/p: {type: std_msgs/Float64, messages: [{at: 1 s, data: 2}]}
    expect:
      - {at: 0.5 s, start: on_abs}
      - {at: 0.5 s, start: on_rel}
      - {at: 1 s, start: on_priv}
""")
    code, out, err = run(capsys, "test", path)
    assert code == 0, out + err
    assert "warning" not in err, err


def test_rule_tests_do_not_feed_a_private_name_from_the_root(write, capsys):
    write("lib.yaml", LIB)
    write("robot.rbs", SPEC)
    path = write("t.test.yaml", """spec: robot.rbs
tests:
  - name: /p is not ~p
    duration: 2 s
    topics:
      /p: {type: std_msgs/Float64, messages: [{at: 0.5 s, data: 2}]}
    expect:
      - {never: on_priv}
""")
    code, out, err = run(capsys, "test", path)
    assert code == 0, out + err
    assert "warning: the spec reads no topic /p" in err, err


def spellings_bag(tmp_path):
    """/x: 0, 2 at 0.5 s, 0 at 2 s; /rubass/p (the spec's ~p): 2 at 1 s."""
    rosbag = pytest.importorskip("rosbag")
    import rospy
    from std_msgs.msg import Float64

    bag = str(tmp_path / "x.bag")
    with rosbag.Bag(bag, "w") as b:
        b.write("/x", Float64(0.0), rospy.Time.from_sec(100.0))
        b.write("/x", Float64(2.0), rospy.Time.from_sec(100.5))
        b.write("/rubass/p", Float64(2.0), rospy.Time.from_sec(101.0))
        b.write("/x", Float64(0.0), rospy.Time.from_sec(102.0))
    return bag


def test_replay_feeds_every_spelling_of_a_topic(write, tmp_path, capsys):
    write("lib.yaml", LIB)
    spec = write("robot.rbs", SPEC)
    bag = spellings_bag(tmp_path)
    code, out, err = run(capsys, "replay", spec, bag, "--json")
    assert code == 0, out + err
    assert "warning" not in err, err
    events = [json.loads(line) for line in out.splitlines()]
    rules = {}
    for e in events:
        if e["event"] == "rule":
            rules.setdefault(e["rule"], []).append((round(e["time"], 3), e["value"]))
    assert rules["e.abs_"] == rules["e.rel_"] == [(0.0, None), (0.0, False), (0.5, True), (2.0, False)]
    assert rules["e.priv_"] == [(0.0, None), (1.0, True)]
    assert rules["e.priv_age"] == [(0.0, False)]
    starts = sorted((e["behaviour"], round(e["time"], 3)) for e in events if e["event"] == "start")
    assert starts == [(1, 0.5), (2, 0.5), (3, 1.0)]


BAD = """import "lib.yaml";
action primitive warn;
entity e {
  rules:
    priv_: topic ~p.dat > 1;
}
if (e.priv_) then { warn; }
"""


def test_a_private_topics_fields_are_checked_against_its_resolved_topic(write, tmp_path, capsys):
    write("lib.yaml", LIB)
    spec = write("robot.rbs", BAD)
    path = write("t.test.yaml", """spec: robot.rbs
tests:
  - name: bad field
    topics:
      /rubass/p: {type: std_msgs/Float64, messages: [{at: 0.5 s, data: 2}]}
""")
    code, out, err = run(capsys, "test", path)
    assert code == 2 and "reads /rubass/p.dat" in err and "has no field 'dat'" in err, out + err
    rosbag = pytest.importorskip("rosbag")
    import rospy
    from std_msgs.msg import Float64

    bag = str(tmp_path / "p.bag")
    with rosbag.Bag(bag, "w") as b:
        b.write("/rubass/p", Float64(2.0), rospy.Time.from_sec(100.0))
    code, out, err = run(capsys, "replay", spec, bag)
    assert code == 1 and f"{spec}:5:12: error: std_msgs/Float64 has no field 'dat'; did you mean 'data'?" in err, \
        out + err  # at its place: the bag's /rubass/p is the model of ~p


def test_the_report_replays_every_spelling_of_a_topic(write, tmp_path):
    """rubass report --bag replays as rubass replay does: each spelling fed (helper finding)."""
    from rubass.lang import load_spec
    from rubass.report.evidence import replay_bag

    write("lib.yaml", LIB)
    spec = load_spec(write("robot.rbs", SPEC))
    bag = spellings_bag(tmp_path)
    run = replay_bag(spec, bag)
    assert not run.error and not run.warnings, (run.error, run.warnings)
    starts = sorted((e.behaviour, round(e.time, 3)) for e in run.events if e.kind == "start")
    assert starts == [(1, 0.5), (2, 0.5), (3, 1.0)]


@pytest.mark.parametrize("name,resolved", [("x", "/robot1/x"), ("/x", "/x"), ("~x", "/robot1/rubass/x"),
                                           ("a/b", "/robot1/a/b"), ("~x/y", "/robot1/rubass/x/y")])
def test_names_resolve_in_ros_namespace_as_rosrun_would_start_the_monitor(name, resolved, monkeypatch):
    """A namespaced robot (an acceptance sweep of bringups): the live monitor in /robot1 reads `cmd_vel` as
    /robot1/cmd_vel, but replay, rule tests and check --live read it as /cmd_vel; with ROS_NAMESPACE set
    (as rosrun reads it) they resolve as that monitor does."""
    monkeypatch.setenv("ROS_NAMESPACE", "robot1")
    assert resolve(name) == resolved
    rosgraph_names = pytest.importorskip("rosgraph.names")
    assert rosgraph_names.resolve_name(name, "/robot1/rubass") == resolved


def test_rule_tests_in_a_namespace_feed_the_namespaced_topic(write, capsys, monkeypatch):
    write("lib.yaml", LIB)
    write("robot.rbs", SPEC)
    path = write("t.test.yaml", """spec: robot.rbs
tests:
  - name: the robot's own topic, in its namespace
    duration: 2 s
    topics:
      /robot1/x: {type: std_msgs/Float64, messages: [{at: 0.5 s, data: 2}]}
    expect:
      - {at: 0.5 s, start: on_rel}
      - {never: on_abs}
""")
    monkeypatch.setenv("ROS_NAMESPACE", "/robot1/")
    code, out, err = run(capsys, "test", path)
    assert code == 0, out + err
    monkeypatch.delenv("ROS_NAMESPACE")
    code, out, err = run(capsys, "test", path)  # at the root, `x` is /x: the test's topic is not read
    assert code == 1 and "warning: the spec reads no topic /robot1/x" in err, out + err
