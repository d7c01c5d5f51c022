"""Arbitration by priority on a live ROS 1 system (LANGUAGE.md §16): several actions on one topic,
only the highest active one publishes; a release hands the topic over at once."""
import pytest

from rosharness import TWIST
from test_limit import between, limit_spec, refused, sent

pytestmark = [pytest.mark.ros, pytest.mark.slow]

ZERO = {"x": 0.0, "y": 0.0, "z": 0.0}
HI, LO = -0.05, 0.11  # linear.x of each action's message, to tell them apart
TWO = ("actions:\n"
       f"  hi: {{plugin: publish, topic: /safety_cmd, type: {TWIST}, message: {{linear: {{x: {HI}}}}}, rate: 20 Hz, "
       "priority: 2}\n"
       # 2 Hz: were the hand-over left to lo's own period, it would take up to 0.5 s
       f"  lo: {{plugin: publish, topic: /safety_cmd, type: {TWIST}, message: {{linear: {{x: {LO}}}}}, rate: 2 Hz, "
       "priority: 1}\n")
TRIGGERS = (("a", "/hi_on", "hi"), ("b", "/lo_on", "lo"))


def xs(msgs):
    return [m["msg"]["linear"]["x"] for m in msgs]


def test_only_the_highest_priority_publishes_and_a_release_hands_over_without_gap_or_stale_message(ros, tmp_path):
    ros.monitor(limit_spec(tmp_path, TWO, "hi, lo", TRIGGERS))
    f64 = "std_msgs/Float64"
    rec = ros.probe({
        "listen": [{"topic": "/safety_cmd", "type": TWIST}],
        "advertise": [{"topic": "/hi_on", "type": f64}, {"topic": "/lo_on", "type": f64}],
        "steps": [{"wait_subscribers": "/hi_on"}, {"wait_subscribers": "/lo_on"}, {"wait_publishers": "/safety_cmd"},
                  {"sleep": 0.5},
                  {"publish": "/lo_on", "msg": {"data": 1.0}}, {"sleep": 1.1},
                  {"publish": "/hi_on", "msg": {"data": 1.0}}, {"sleep": 1.0},
                  {"publish": "/hi_on", "msg": {"data": 0.0}}, {"sleep": 1.1},
                  {"publish": "/lo_on", "msg": {"data": 0.0}}, {"sleep": 0.6}],
        "linger": 0.1})
    lo_on, hi_on, hi_off, lo_off = (sent(rec, "/lo_on", 0), sent(rec, "/hi_on", 0), sent(rec, "/hi_on", 1),
                                    sent(rec, "/lo_on", 1))
    assert set(xs(between(rec, lo_on, hi_on))) == {LO}
    during = between(rec, hi_on, hi_off)
    switch = xs(during).index(HI)
    assert switch <= 1 and during[switch]["wall"] - hi_on < 0.1, xs(during)  # one lo message in flight at most
    assert set(xs(during[switch:])) == {HI}, xs(during)  # then lo waits: not one of its messages while hi is active
    assert 15 <= len(during) <= 25  # hi at 20 Hz for 1 s
    after = between(rec, hi_off, lo_off)
    # handed over at once (lo's own period is 0.5 s), and nothing of hi once lo has the topic
    assert after[0]["wall"] - hi_off < 0.15, after[0]["wall"] - hi_off
    first_lo = next(i for i, m in enumerate(after) if m["msg"]["linear"]["x"] == LO)
    assert set(xs(after[first_lo:])) == {LO} and first_lo <= 1
    # no gap longer than one period of the action that publishes (lo: 0.5 s; hi: 0.05 s), load allowing
    msgs = between(rec, lo_on, lo_off)
    gaps = [(b["wall"] - a["wall"], a["msg"]["linear"]["x"], b["msg"]["linear"]["x"]) for a, b in zip(msgs, msgs[1:])]
    assert max(g for g, _, _ in gaps) < 0.5 + 0.15, gaps
    assert max(g for g, x, y in gaps if x == y == HI) < 0.05 + 0.05, gaps
    assert between(rec, lo_off + 0.05, 1e12) == []


STOP_CRAWL = ("actions:\n"
              f"  stop: {{plugin: publish, topic: /safety_cmd, type: {TWIST}, message: {{}}, rate: 20 Hz, "
              "priority: 2}\n"
              "  crawl:\n    plugin: limit\n    input: /cmd_vel\n    topic: /safety_cmd\n"
              "    linear_x: [-0.1 m/s, 0.2 m/s]\n    priority: 1\n")


def test_a_stop_over_a_limit_then_the_limit_takes_over_with_fresh_commands(ros, tmp_path):
    ros.monitor(limit_spec(tmp_path, STOP_CRAWL, "stop, crawl", (("a", "/stop_on", "stop"), ("b", "/crawl_on", "crawl"))))
    f64 = "std_msgs/Float64"
    rec = ros.probe({
        "listen": [{"topic": "/safety_cmd", "type": TWIST}],
        "advertise": [{"topic": "/cmd_vel", "type": TWIST}, {"topic": "/stop_on", "type": f64},
                      {"topic": "/crawl_on", "type": f64}],
        "steps": [{"wait_subscribers": "/cmd_vel"}, {"wait_subscribers": "/stop_on"},
                  {"wait_publishers": "/safety_cmd"}, {"sleep": 0.5},
                  {"publish": "/stop_on", "msg": {"data": 1.0}}, {"publish": "/crawl_on", "msg": {"data": 1.0}},
                  {"sleep": 0.3},
                  {"publish": "/cmd_vel", "msg": {"linear": {"x": 1.0}}, "repeat": 10, "period": 0.05},
                  {"publish": "/stop_on", "msg": {"data": 0.0}},
                  {"publish": "/cmd_vel", "msg": {"linear": {"x": 1.0}}, "repeat": 10, "period": 0.05},
                  {"sleep": 0.2}],
        "linger": 0.1})
    on, off = sent(rec, "/stop_on", 0), sent(rec, "/stop_on", 1)
    during = between(rec, on, off)
    assert len(during) >= 7 and all(m["msg"] == {"linear": ZERO, "angular": ZERO} for m in during), during
    after = between(rec, off, sent(rec, "/cmd_vel") + 0.01)
    # the limit is heard at once with the latest command clamped (one zero of the stop in flight at
    # most), and no zero of the stop after it
    back = xs(after).index(0.2)
    assert back <= 1 and after[back]["wall"] - off < 0.1 and xs(after[back:]) == [0.2] * (len(after) - back), xs(after)
    assert len(after) - back >= 10


def test_one_priority_twice_on_one_topic_across_libraries_is_refused(ros, tmp_path):
    (tmp_path / "other.yaml").write_text(
        f"actions:\n  brake:\n    plugin: publish\n    topic: safety_cmd\n    type: {TWIST}\n")
    path = limit_spec(tmp_path, f"actions:\n  stop: {{plugin: publish, topic: /safety_cmd, type: {TWIST}}}\n",
                      "stop, brake", (("a", "/a", "stop"), ("b", "/b", "brake")))
    out = refused(ros, path, f"_actions:=[{tmp_path / 'other.yaml'}]")
    assert (f"other.yaml:2:3: error: action 'brake': same priority (0) as action 'stop' ({tmp_path}/lib.yaml:2:3), "
            "and both publish on /safety_cmd") in out, out


TWO_LIMITS = ("actions:\n"
              "  back_away:\n    plugin: limit\n    input: /cmd_vel\n    topic: /safety_cmd\n"
              "    linear_x: [-0.1 m/s, 0]\n    angular_z: [0, 0]\n    priority: 2\n"
              "  crawl:\n    plugin: limit\n    input: /cmd_vel\n    topic: /safety_cmd\n"
              "    linear_x: [-0.1 m/s, 0.2 m/s]\n    priority: 1\n")


def test_two_limits_on_one_input_the_higher_clamps_and_its_release_hands_back_at_once(ros, tmp_path):
    ros.monitor(limit_spec(tmp_path, TWO_LIMITS, "back_away, crawl",
                           (("a", "/bump", "back_away"), ("b", "/near", "crawl"))))
    f64 = "std_msgs/Float64"
    cmd = {"linear": {"x": 1.0}, "angular": {"z": 0.4}}
    rec = ros.probe({
        "listen": [{"topic": "/safety_cmd", "type": TWIST}],
        "advertise": [{"topic": "/cmd_vel", "type": TWIST}, {"topic": "/bump", "type": f64},
                      {"topic": "/near", "type": f64}],
        "steps": [{"wait_subscribers": "/cmd_vel"}, {"wait_subscribers": "/bump"}, {"wait_subscribers": "/near"},
                  {"wait_publishers": "/safety_cmd"}, {"sleep": 0.5},
                  {"publish": "/near", "msg": {"data": 1.0}}, {"sleep": 0.3},  # crawl's start: zero, no command yet
                  {"publish": "/cmd_vel", "msg": cmd, "repeat": 6, "period": 0.05},
                  {"publish": "/bump", "msg": {"data": 1.0}},
                  {"publish": "/cmd_vel", "msg": cmd, "repeat": 8, "period": 0.05},
                  {"publish": "/bump", "msg": {"data": 0.0}},
                  {"publish": "/cmd_vel", "msg": cmd, "repeat": 8, "period": 0.05}, {"sleep": 0.1}],
        "linger": 0.1})
    bump_on, bump_off = sent(rec, "/bump", 0), sent(rec, "/bump", 1)
    first_cmd = sent(rec, "/cmd_vel", 0)
    before = between(rec, first_cmd, bump_on)
    clamped = next(i for i, m in enumerate(before) if m["msg"]["linear"]["x"] == 0.2)
    # a zero crawl had in flight as the first command came, at most (seen on a slower machine)
    assert clamped <= 1 and before[clamped]["wall"] - first_cmd < 0.1, xs(before)
    assert xs(before[clamped:]) == [0.2] * (len(before) - clamped) and len(before) - clamped >= 5, xs(before)
    during = between(rec, bump_on, bump_off)
    switch = next(i for i, m in enumerate(during) if m["msg"]["linear"]["x"] == 0.0)
    assert during[switch]["wall"] - bump_on < 0.1 and switch <= 1, during  # a command crawl had in hand at most
    assert len(during) - switch >= 6 and all(m["msg"]["linear"]["x"] == 0.0 and m["msg"]["angular"]["z"] == 0.0
                                             for m in during[switch:]), during  # none of crawl's after the switch
    after = between(rec, bump_off, 1e12)
    back = next(i for i, m in enumerate(after) if m["msg"]["linear"]["x"] == 0.2)
    assert after[back]["wall"] - bump_off < 0.1 and back <= 1, xs(after)  # a command back_away had in hand at most
    assert xs(after[back:]) == [0.2] * (len(after) - back), xs(after)  # none of back_away's after the hand-over
    assert after[back]["msg"]["angular"]["z"] == pytest.approx(0.4)
