"""Arbitration by priority and velocity clamping: the pure logic of LANGUAGE.md §16."""
import math
import threading
from types import SimpleNamespace

from rubass.actions.arbitration import Arbiter
from rubass.actions.clamp import clamp, clamp_twist


def seats(*specs):
    arb, handed = Arbiter(), []
    out = [arb.seat(topic, name, prio, lambda name=name: handed.append(name)) for topic, name, prio in specs]
    return arb, out, handed


def test_only_the_highest_active_priority_owns_the_topic():
    arb, (stop, crawl), handed = seats(("/cmd", "stop", 2), ("/cmd", "crawl", 1))
    assert arb.owner("/cmd") is None
    crawl.activate()
    assert crawl.owner and not stop.owner
    stop.activate()
    assert stop.owner and not crawl.owner
    assert handed == []  # a seat that outranks the owner publishes at its own start: nobody is woken
    assert arb.describe("/cmd") == "stop (waiting: crawl)"


def test_releasing_the_owner_hands_the_topic_to_the_next_active_one():
    arb, (stop, crawl, idle), handed = seats(("/cmd", "stop", 2), ("/cmd", "crawl", 1), ("/cmd", "idle", 0))
    crawl.activate()
    stop.activate()
    stop.deactivate()
    assert crawl.owner and handed == ["crawl"]
    crawl.deactivate()
    assert arb.owner("/cmd") is None and handed == ["crawl"]  # idle is not active: nobody takes over


def test_releasing_a_waiting_action_changes_nothing():
    arb, (stop, crawl), handed = seats(("/cmd", "stop", 2), ("/cmd", "crawl", 1))
    stop.activate()
    crawl.activate()
    crawl.deactivate()
    assert stop.owner and handed == []


def test_topics_are_independent_and_negative_priorities_work():
    arb, (a, b, c), handed = seats(("/a", "a", -5), ("/b", "b", 7), ("/a", "c", -6))
    a.activate()
    b.activate()
    c.activate()
    assert a.owner and b.owner and not c.owner
    a.leave()
    assert c.owner and handed == ["c"]
    assert arb.describe("/b") == "b"


def test_equal_priorities_during_a_reload_keep_the_older_seat():
    arb, (old, new), handed = seats(("/cmd", "stop", 2), ("/cmd", "stop", 2))
    old.activate()
    new.activate()
    assert old.owner
    old.leave()  # the reload closes the old version: the new one carries on at once
    assert new.owner and handed == ["stop"]


def test_turn_holds_ownership_while_publishing():
    arb, (stop, crawl), _ = seats(("/cmd", "stop", 2), ("/cmd", "crawl", 1))
    crawl.activate()
    published, entered = [], threading.Event()
    release = threading.Event()

    def publish_slowly():
        with crawl.turn() as mine:
            entered.set()
            release.wait(2)
            if mine:
                published.append("crawl")

    t = threading.Thread(target=publish_slowly)
    t.start()
    entered.wait(2)
    starter = threading.Thread(target=stop.activate)
    starter.start()
    starter.join(0.1)
    assert starter.is_alive()  # stop's start waits until crawl's publication is over
    release.set()
    t.join(2)
    starter.join(2)
    assert published == ["crawl"] and stop.owner
    with crawl.turn() as mine:
        assert not mine  # after stop's start, crawl can no longer publish


def test_clamp_bounds_values_and_turns_nan_into_the_value_nearest_zero():
    assert clamp(0.5, -0.1, 0.2) == 0.2
    assert clamp(-0.5, -0.1, 0.2) == -0.1
    assert clamp(0.05, -0.1, 0.2) == 0.05
    assert clamp(float("inf"), -0.1, 0.2) == 0.2
    assert clamp(float("nan"), -0.1, 0.2) == 0.0
    assert clamp(float("nan"), 0.1, 0.2) == 0.1  # only forward allowed: NaN becomes the slowest forward
    assert clamp(float("nan"), -0.3, -0.1) == -0.1


def test_clamp_twist_touches_only_named_axes():
    twist = SimpleNamespace(linear=SimpleNamespace(x=1.0, y=2.0, z=3.0),
                            angular=SimpleNamespace(x=4.0, y=5.0, z=-2.0))
    clamp_twist(twist, {"linear_x": (-0.1, 0.2), "angular_z": (-0.5, 0.5), "linear_y": None})
    assert (twist.linear.x, twist.linear.y, twist.linear.z) == (0.2, 2.0, 3.0)
    assert (twist.angular.x, twist.angular.y, twist.angular.z) == (4.0, 5.0, -0.5)
    assert not math.isnan(twist.linear.x)
