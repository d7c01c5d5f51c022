"""`rubass replay` fixes of the acceptance sweep. Pure (no ROS): recorded node samples reach every
spelling of their node; messages of one topic sharing a timestamp are each evaluated. On bags written
with the rosbag API (no master): node samples under another spelling, every recorded type of a topic
checked, the spec's warnings, a recording spanning days, a bag given as the spec."""
import json
import os
import subprocess
import sys

import pytest

from rubass.lang import check_text
from rubass.replay.agents import agent_samples
from rubass.replay.command import _sampled_nodes
from rubass.replay.run import replay as replay_loop, resolve_node

from conftest import ROOT

try:  # ROS 1 only from /usr/bin/python3: the tests on bags are skipped elsewhere
    import rosbag
    import rospy
    from geometry_msgs.msg import Twist
    from std_msgs.msg import Float64, String
except ImportError:
    rosbag = None

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")
T0 = 1700000000.0
START = T0


# -- pure: the replay loop ------------------------------------------------------------------------
class Sample:
    def __init__(self, data):
        self.data = data


def node_spec(*spellings):
    rules = "".join(f"  dead{i}: not alive(node {n});\n" for i, n in enumerate(spellings))
    behaviours = "".join(f"if (r.dead{i}) then {{ stop; }}\n" for i in range(len(spellings)))
    text = f"action primitive stop;\nentity r: {', '.join(spellings)} {{ rules:\n" + rules + "}\n" + behaviours
    return check_text(text, os.path.join(ROOT, "n.rbs"), [LIB])


def samples(name, topic="/rubass/node_samples", dead_at=2.0):
    out = []
    for i in range(40):
        t = START + i * 0.1
        alive = t < START + dead_at - 1e-9
        out.append((t, topic, Sample(json.dumps({"node": name, "time": t - 0.003, "alive": alive}))))
    return out


def starts(events):
    return sorted((e.behaviour, round(e.time, 3)) for e in events if e.kind == "start")


# -- 1. node samples reach every spelling of their node --------------------------------------------
def test_a_sample_recorded_relative_reaches_an_absolute_spelling():
    spec = node_spec("/controller")
    _, events = replay_loop(spec, iter(samples("controller")), START, START + 4.0, 50.0, ["/rubass/node_samples"])
    assert starts(events) == [(1, 1.997)]  # before the fix: unknown, no start


def test_a_sample_recorded_absolute_reaches_a_relative_spelling():
    spec = node_spec("controller")
    _, events = replay_loop(spec, iter(samples("/controller")), START, START + 4.0, 50.0, ["/rubass/node_samples"])
    assert starts(events) == [(1, 1.997)]


def test_both_spellings_get_samples_of_either():
    spec = node_spec("controller", "/controller")
    _, events = replay_loop(spec, iter(samples("/controller")), START, START + 4.0, 50.0, ["/rubass/node_samples"])
    assert starts(events) == [(1, 1.997), (2, 1.997)]


def test_a_spelling_recorded_itself_gets_only_its_own_samples():
    # a monitor sampled both spellings: each spelling's own samples, not the other's (here they differ)
    spec = node_spec("controller", "/controller")
    seq = sorted(samples("controller", dead_at=2.0) + samples("/controller", dead_at=3.0), key=lambda x: x[0])
    _, events = replay_loop(spec, iter(seq), START, START + 4.0, 50.0, ["/rubass/node_samples"])
    assert starts(events) == [(1, 1.997), (2, 2.997)]


def test_names_resolve_in_the_recording_monitors_namespace():
    # `controller` sampled by the monitor /ns/rubass is /ns/controller, not /controller
    topic = "/ns/rubass/node_samples"
    spec = node_spec("/controller", "/ns/controller")
    _, events = replay_loop(spec, iter(samples("controller", topic)), START, START + 4.0, 50.0, [topic])
    assert starts(events) == [(2, 1.997)]
    assert resolve_node("controller", "/ns/rubass") == "/ns/controller"
    assert resolve_node("~x", "/ns/rubass") == "/ns/rubass/x"
    assert resolve_node("a/b") == "/a/b"


def test_agents_leave_a_node_the_monitor_sampled_under_another_spelling():
    covered = _sampled_nodes(samples("controller")[:1])
    assert covered == {"/controller"}
    report = json.dumps({"agent": "/agent_a", "host": "a", "period": 1.0, "time": 0.5,
                         "nodes": [{"node": "/controller", "time": 0.5, "alive": True, "cpu": 0.5, "memory": 1e6}]})
    stream = [(0.5, "/rubass/agent_samples", Sample(report))]
    out = list(agent_samples(iter(stream), {"/rubass/agent_samples"}, {"/controller": "controller"}, covered, end=1.0))
    assert out == []  # before the fix: the agents' samples too, beside the monitor's own


# -- 2. messages of one topic at one timestamp ------------------------------------------------------
def over_spec():
    return check_text("action primitive stop;\nentity e { rules:\n  over: topic /x.v > 1;\n"
                      "  both: topic /x.v > 1 and topic /y.v > 1;\n}\n"
                      "if (e.over) then { stop; }\nif (e.both) then { stop; }\n",
                      os.path.join(ROOT, "s.rbs"), [LIB])


def test_two_messages_of_one_topic_at_one_instant_are_each_evaluated():
    seq = [(START, "/x", {"v": 0.0}), (START + 1, "/x", {"v": 2.0}), (START + 1, "/x", {"v": 0.0}),
           (START + 3, "/x", {"v": 0.0})]
    _, events = replay_loop(over_spec(), iter(seq), START, START + 3.0)
    assert [(e.kind, e.behaviour, e.time) for e in events if e.kind == "start"] == [("start", 1, 1.0)]
    # before the fix: no start (the 2.0 was overwritten by the 0.0); now it is true, then false, at 1 s
    assert [(e.time, e.value) for e in events if e.rule == "e.over"][-2:] == [(1.0, True), (1.0, False)]


def test_messages_of_different_topics_at_one_instant_stay_one_evaluation():
    # /x high and /y low at one instant, then /y high with /x low at the next: never both high
    seq = [(START + 1, "/x", {"v": 2.0}), (START + 1, "/y", {"v": 0.0}),
           (START + 2, "/y", {"v": 2.0}), (START + 2, "/x", {"v": 0.0})]
    _, events = replay_loop(over_spec(), iter(seq), START, START + 3.0)
    assert not [e for e in events if e.kind == "start" and e.behaviour == 2]


# -- the command, on recorded bags -----------------------------------------------------------------
def write_bag(path, items):
    with rosbag.Bag(path, "w") as bag:
        for t, topic, msg in items:
            bag.write(topic, msg, rospy.Time.from_sec(T0 + t))
    return path


def spec_file(write, body, actions="stop"):
    return write("s.rbs", f'import "{LIB}";\naction primitive {actions};\n' + body)


def replay(*args):
    proc = subprocess.run([sys.executable, "-m", "rubass", "replay", *args], cwd=ROOT, capture_output=True,
                          text=True, timeout=300)
    assert "Traceback" not in proc.stderr, proc.stderr
    return proc


def node_bag(path, name="controller"):
    items = []
    for i in range(40):
        t = i * 0.1
        d = {"node": name, "time": T0 + t - 0.003, "alive": t < 2.0 - 1e-9, "cpu": 0.1, "memory": 1e6}
        items.append((t, "/rubass/node_samples", String(data=json.dumps(d))))
    return write_bag(path, items)


@pytest.mark.ros
@pytest.mark.skipif(rosbag is None, reason="needs ROS 1 (rosbag)")
def test_a_node_sample_recorded_relative_reaches_the_absolute_spelling(write, tmp_path):
    bag = node_bag(str(tmp_path / "n.bag"))
    spec = spec_file(write, "entity base: /controller { rules: dead: not alive(node /controller); }\n"
                            "if (base.dead) then { stop; }\n")
    proc = replay(spec, bag, "--json")
    assert proc.returncode == 0, proc.stderr
    starts = [x for x in map(json.loads, proc.stdout.splitlines()) if x["event"] == "start"]
    assert [round(x["time"], 3) for x in starts] == [1.997]  # before: unknown all along, no stop
    assert "warning" not in proc.stderr


@pytest.mark.ros
@pytest.mark.skipif(rosbag is None, reason="needs ROS 1 (rosbag)")
def test_a_warning_for_a_node_no_recorded_sample_covers(write, tmp_path):
    bag = node_bag(str(tmp_path / "n.bag"))
    spec = spec_file(write, "entity base: controller, planner { rules:\n  dead: not alive(node controller);\n"
                            "  gone: not alive(node planner);\n}\nif (base.dead or base.gone) then { stop; }\n")
    proc = replay(spec, bag)
    assert proc.returncode == 0, proc.stderr
    assert "warning: the recording has node samples, but none of node planner (/planner)" in proc.stderr
    assert "node controller" not in proc.stderr


def two_type_bag(tmp_path, second):
    """/speed recorded as std_msgs/Float64, then as `second` (rosbag's writer keeps one type per topic:
    written under another name of the same length, renamed in the file)."""
    pre = write_bag(str(tmp_path / "pre.bag"), [(i * 0.1, "/speed", Float64(data=1.0)) for i in range(10)] +
                    [(1 + i * 0.1, "/speex", second) for i in range(10)])
    path = str(tmp_path / "two.bag")
    with open(pre, "rb") as src, open(path, "wb") as out:
        out.write(src.read().replace(b"/speex", b"/speed"))
    return path


def twist():
    m = Twist()
    m.linear.x = 1.0
    return m


@pytest.mark.ros
@pytest.mark.skipif(rosbag is None, reason="needs ROS 1 (rosbag)")
@pytest.mark.parametrize("second, said", [("twist", "geometry_msgs/Twist has no field 'data'"),
                                          ("string", "'>' needs a number, not a string")])
def test_every_recorded_type_of_a_topic_is_checked(write, tmp_path, second, said):
    second = twist() if second == "twist" else String(data="x")
    bag = two_type_bag(tmp_path, second)
    line = "entity e { rules: fast: topic /speed.data > 0.5 for 1 s; }"
    spec = spec_file(write, line + "\nif (e.fast) then { stop; }\n")
    proc = replay(spec, bag)
    assert proc.returncode == 1, proc.stdout  # before: exit 0, the second type's messages unknown
    assert f"{spec}:3:{line.index('topic') + 1}: error: {said}" in proc.stderr
    note = (f"; /speed is recorded as {type(second)._type} too in {os.path.basename(bag)} (first as "
            f"std_msgs/Float64): this is the spec read against {type(second)._type}")  # as `check --bag` says it
    assert any(said in line and line.endswith(note) for line in proc.stderr.splitlines()), proc.stderr
    assert proc.stdout == ""
    from rubass.lang import load_spec
    from rubass.report.evidence import replay_bag

    run = replay_bag(load_spec(spec, []), bag)  # `rubass report --bag`: the same check
    assert run.error and any(said in e for e in run.type_errors)


@pytest.mark.ros
@pytest.mark.skipif(rosbag is None, reason="needs ROS 1 (rosbag)")
def test_the_specs_warnings_come_before_the_replay(write, tmp_path):
    bag = write_bag(str(tmp_path / "x.bag"), [(0.0, "/x", Float64(data=0)), (1.0, "/x", Float64(data=2))])
    spec = spec_file(write, "entity e { rules:\n  f: topic /x.data > 1;\n  s: stamp_age(topic /x) > 1 s;\n}\n"
                            "if (e.f) then { warn; }\n", actions="warn, stop")
    proc = replay(spec, bag)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stderr.splitlines()
    assert lines[0] == f"{spec}:2:24: warning: action 'stop' is declared but never used", proc.stderr
    assert any(line.startswith(f"{spec}:5:16: warning: stamp_age(topic /x) is always unknown") for line in lines)


@pytest.mark.ros
@pytest.mark.skipif(rosbag is None, reason="needs ROS 1 (rosbag)")
def test_a_recording_spanning_days_is_warned_of(write, tmp_path):
    bag = write_bag(str(tmp_path / "stray.bag"), [(-2.5 * 86400, "/x", Float64(data=0))] +
                    [(i * 0.1, "/x", Float64(data=2)) for i in range(5)])
    spec = spec_file(write, "entity e { rules: over: topic /x.data > 1; }\nif (e.over) then { stop; }\n")
    proc = replay(spec, bag, "--rate", "0.1")
    assert proc.returncode == 0, proc.stderr
    first = proc.stderr.splitlines()[0]
    assert first.startswith("rubass replay: warning: the recording spans 2.5 days; its longest gap, 2.5 days "
                            f"with no message, is from {T0 - 2.5 * 86400:.3f} to {T0:.3f} (bag time, s): "
                            "ticking across it at 0.1 Hz takes about "), first


@pytest.mark.ros
@pytest.mark.skipif(rosbag is None, reason="needs ROS 1 (rosbag)")
def test_a_bag_given_as_the_spec(write, tmp_path):
    bag = write_bag(str(tmp_path / "x.bag"), [(0.0, "/x", Float64(data=0))])
    spec = spec_file(write, "entity e { rules: over: topic /x.data > 1; }\nif (e.over) then { stop; }\n")
    proc = replay(bag, spec)
    assert proc.returncode == 1
    assert proc.stderr == f"rubass replay: error: {bag} is a ROS bag, not a spec (usage: rubass replay SPEC BAG)\n"
