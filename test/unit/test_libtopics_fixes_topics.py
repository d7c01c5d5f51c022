"""Actions on the monitor's own topics, limits fed by an action's output (a loop), and a reload
that would change the type of a topic the running monitor publishes (libtopics.py)."""
import subprocess
import sys

import pytest

from rubass.lang.library import parse_library, priority_conflicts
from rubass.lang.libtopics import MONITOR_TOPICS, running_type_changes
from rubass.lang.source import Source
from rubass.lang.topicnames import resolve


def lib(text, name="lib.yaml"):
    actions, diags = parse_library(Source(name, text))
    return actions, [(d.span.line, d.span.col, d.message) for d in diags]


def pub(name, topic, typ="std_msgs/String", extra=""):
    return f"  {name}:\n    plugin: publish\n    topic: {topic}\n    type: {typ}\n{extra}"


def limit(name, source, topic, extra=""):
    return f"  {name}:\n    plugin: limit\n    input: {source}\n    topic: {topic}\n    linear_x: [-0.1 m/s, 0.1 m/s]\n{extra}"


# -- 2. the monitor's own topics ---------------------------------------------------------------------
@pytest.mark.parametrize("topic,resolved", [
    ("~heartbeat", "~heartbeat"), ("/rubass/heartbeat", "/rubass/heartbeat"), ("~events", "~events"),
    ("~node_samples", "~node_samples"), ("rubass/events/", "/rubass/events"), ("/diagnostics", "/diagnostics"), ("diagnostics", "/diagnostics"),
    ("/rosout", "/rosout"), ("/rubass/agent_samples", "/rubass/agent_samples")])
def test_publishing_on_a_monitor_topic_is_an_error_at_its_topic(topic, resolved):
    actions, diags = lib("actions:\n" + pub("hbx", topic, extra="    message: {data: x}\n"))
    assert "hbx" not in actions
    assert len(diags) == 1
    line, col, msg = diags[0]
    assert (line, col) == (4, 12)  # the value of its 'topic:'
    assert msg.startswith(f"action 'hbx': publishes std_msgs/String on {resolved}, the monitor's own topic")
    assert "give it another topic" in msg


def test_the_same_type_on_the_heartbeat_is_an_error_too():
    """A forged heartbeat of the right type would feed the watchdog while the monitor is dead."""
    _, diags = lib("actions:\n" + pub("hb", "~heartbeat", "std_msgs/Header"))
    assert [d[2].split(":")[0] for d in diags] == ["action 'hb'"]
    assert "its heartbeat (std_msgs/Header)" in diags[0][2]


def test_a_limit_on_a_monitor_topic_is_an_error_output_and_input():
    _, diags = lib("actions:\n" + limit("a", "/nav", "/diagnostics") + limit("b", "~events", "/safe_b"))
    assert [(d[0], d[2].split(",")[0]) for d in diags] == [
        (5, "action 'a': publishes geometry_msgs/Twist on /diagnostics"),
        (9, "action 'b': reads its input from ~events")]


def test_own_topics_resolve_under_the_monitors_node_name():
    """At start and reload the monitor resolves with its own name: ~heartbeat of /safety is /safety/heartbeat."""
    actions, _ = lib("actions:\n" + pub("a", "/safety/heartbeat") + pub("b", "/rubass/heartbeat"))
    as_safety = priority_conflicts(actions.values(), lambda n: resolve(n, "/safety"))
    assert [d.subject for d in as_safety] == ["a"]


def test_other_topics_and_log_actions_are_fine():
    _, diags = lib("actions:\n" + pub("a", "/rubass/heartbeats") + pub("b", "/diagnostics_agg")
                   + "  w:\n    plugin: log\n")
    assert diags == []


def test_the_names_match_the_monitors_publishers():
    """MONITOR_TOPICS names what outputs.py and agentbook.py use (the pure room keeps a copy)."""
    with open("rubass/ros/outputs.py") as f:
        outputs = f.read()
    for name in ("~events", "~heartbeat", "/diagnostics", "~node_samples"):
        assert f'"{name}"' in outputs and name in MONITOR_TOPICS
    code = "from rubass.ros.agentbook import AGENT_TOPIC; print(AGENT_TOPIC)"
    topic = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    if topic.returncode == 0:  # without ROS Python the module does not import
        assert topic.stdout.strip() in MONITOR_TOPICS


# -- 4. a limit fed by an action's output ------------------------------------------------------------
def test_two_limits_feeding_each_other_are_an_error_naming_both():
    actions, diags = lib("actions:\n" + limit("a", "/x", "/y") + limit("b", "/y", "/x", "    priority: 1\n"))
    assert list(actions) == ["a"]
    assert diags == [(9, 12, "action 'b': its input /y is where action 'a' (line 2) publishes: a limit must read "
                             "the robot's own commands (the planner's topic), not an action's output (limits "
                             "feeding each other loop forever)")]


def test_an_output_onto_an_earlier_limits_input_is_an_error_at_its_topic():
    _, diags = lib("actions:\n" + limit("a", "/nav", "/safe") + pub("stop", "nav", "geometry_msgs/Twist"))
    assert diags == [(9, 12, "action 'stop': publishes on /nav, the input of limit 'a' (line 2): a limit must read "
                             "the robot's own commands (the planner's topic), not an action's output (limits "
                             "feeding each other loop forever)")]


def test_a_chain_of_limits_is_an_error_and_limits_sharing_an_input_are_not():
    _, chain = lib("actions:\n" + limit("a", "/nav", "/mid") + limit("b", "/mid", "/out"))
    assert [d[2].split(":")[0] for d in chain] == ["action 'b'"]
    _, shared = lib("actions:\n" + limit("crawl", "/nav", "/safe", "    priority: 1\n")
                    + limit("back", "/nav", "/safe", "    priority: 2\n") + pub("stop", "/safe", "geometry_msgs/Twist",
                                                                              "    priority: 3\n"))
    assert shared == []


def test_a_loop_across_two_libraries_is_reported_by_check(tmp_path):
    (tmp_path / "a.yaml").write_text("actions:\n" + limit("a", "/x", "/y"))
    (tmp_path / "b.yaml").write_text("actions:\n" + limit("b", "/y", "/x"))
    (tmp_path / "s.rbs").write_text('import "a.yaml"; import "b.yaml";\naction primitive a, b;\n'
                                    'entity e { rules: r: topic /t.data > 1; }\nif (e.r) then { a; b; }\n')
    r = subprocess.run([sys.executable, "-m", "rubass", "check", str(tmp_path / "s.rbs")], capture_output=True,
                       text=True)
    assert r.returncode != 0
    assert "b.yaml:4:12: error: action 'b': its input /y is where action 'a' (" in r.stdout + r.stderr


# -- 1. a reload that changes the type of a topic the monitor publishes -----------------------------
def test_a_new_type_on_a_running_topic_is_an_error_naming_both_types_and_the_place():
    old, _ = lib("actions:\n" + pub("stop", "/safe", "geometry_msgs/Twist") + limit("crawl", "/nav", "/safe",
                                                                                  "    priority: 1\n"), "old.yaml")
    new, diags = lib("actions:\n" + pub("stop", "/safe", "geometry_msgs/TwistStamped")
                     + limit("crawl", "/nav_s", "/safe", "    priority: 1\n    type: geometry_msgs/TwistStamped\n"),
                     "new.yaml")
    assert diags == []
    errs = running_type_changes(old.values(), new.values())
    assert [(str(d.span), d.subject) for d in errs] == [("new.yaml:5:11", "stop"), ("new.yaml:12:11", "crawl")]
    msg = errs[0].message
    assert msg.startswith("action 'stop': publishes geometry_msgs/TwistStamped on /safe, but the running monitor "
                          "publishes geometry_msgs/Twist there (action 'stop', old.yaml:2:3)")
    assert "restart the monitor to change the type of /safe" in msg


def test_same_types_new_topics_and_spellings():
    old, _ = lib("actions:\n" + pub("stop", "/safe", "geometry_msgs/Twist"))
    same, _ = lib("actions:\n" + pub("halt", "safe", "geometry_msgs/Twist"))
    moved, _ = lib("actions:\n" + pub("stop", "/safe2", "geometry_msgs/TwistStamped"))
    respelt, _ = lib("actions:\n" + pub("stop", "safe/", "geometry_msgs/TwistStamped"))
    assert running_type_changes(old.values(), same.values()) == []
    assert running_type_changes(old.values(), moved.values()) == []
    assert [d.subject for d in running_type_changes(old.values(), respelt.values())] == ["stop"]
    assert running_type_changes([], respelt.values()) == []  # nothing published yet: any type


def test_the_docs_quote_the_error_as_it_is():
    import os

    from conftest import ROOT

    text = open(os.path.join(ROOT, "docs", "actions.md"), encoding="utf-8").read()
    _, diags = parse_library(Source("lib.yaml", "actions:\n  stop: {plugin: publish, topic: /safe, type: geometry_msgs/Twist}\n"
                                    '  hbx: {plugin: publish, topic: ~heartbeat, type: std_msgs/String, message: {data: "x"}}\n'))
    assert len(diags) == 1
    assert f"{diags[0].span}: error: {diags[0].message}\n" in text
