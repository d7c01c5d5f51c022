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


def test_actions_that_start_in_one_instant_let_the_highest_priority_publish_first(tmp_path):
    """Acceptance finding: `then { crawl; back_away; stop; }` on one topic: crawl's runner took the
    topic and published before stop's runner had activated its seat (3 starts in 4, within 1 ms).
    The dispatcher now claims every start of the instant before it wakes any runner."""
    import time as _time

    from rubass.actions.base import ActionPlugin
    from rubass.actions.dispatch import Dispatcher
    from rubass.actions.runner import ActionRunner
    from rubass.engine import Event
    from rubass.lang import check_text
    from rubass.lang.library import ActionDef

    arb, published = Arbiter(), []

    class Seated(ActionPlugin):
        def __init__(self, name, priority, delay):
            super().__init__(ActionDef(name, "fake", {}, priority=priority))
            self.seat, self.delay = arb.seat("/cmd", name, priority), delay

        def claim(self):
            self.seat.claim()

        def start(self, ctx):
            _time.sleep(self.delay)  # stop's runner is the slow one to wake
            self.seat.activate()
            with self.seat.turn() as mine:
                if mine:
                    published.append(self.name)

    lib = tmp_path / "lib.yaml"
    lib.write_text("actions:\n  crawl: {plugin: log}\n  stop: {plugin: log}\n")
    spec = check_text("action primitive crawl, stop;\nentity e { rules: r: topic /x.data > 1; }\n"
                      "if (e.r) then { crawl; stop; }\n", extra_libraries=[str(lib)])
    plugins = {"crawl": Seated("crawl", 1, 0.0), "stop": Seated("stop", 2, 0.2)}
    runners = {name: ActionRunner(p, lambda level, text: None) for name, p in plugins.items()}
    for r in runners.values():
        r.start_thread()
    try:
        engine = SimpleNamespace(spec=spec, behaviour_rules=lambda index: [])
        Dispatcher(runners, lambda record: None, lambda: 0.0).handle(engine, [Event(0.0, "start", 1)], "test")
        end = _time.monotonic() + 3
        while "stop" not in published and _time.monotonic() < end:
            _time.sleep(0.01)
        assert published == ["stop"]  # crawl never owned the topic
    finally:
        for r in runners.values():
            r.stop()


def test_a_claimed_start_dropped_unrun_from_a_full_queue_gives_the_topic_back():
    """The runner's queue drops a start whose release follows it (the pair is moot): the seat the
    dispatcher claimed for that start must not stay active, or it would silence lower actions."""
    import collections

    from rubass.actions.base import ActionPlugin, Context
    from rubass.actions.runner import ActionRunner
    from rubass.lang.library import ActionDef

    arb = Arbiter()
    unclaims = []

    class Seated(ActionPlugin):
        def __init__(self, name, priority):
            super().__init__(ActionDef(name, "fake", {}, priority=priority))
            self.seat = arb.seat("/cmd", name, priority)

        def claim(self):
            self.seat.claim()

        def unclaim(self):
            unclaims.append(self.name)
            self.seat.unclaim()

    crawl, stop = Seated("crawl", 1), Seated("stop", 2)
    crawl.seat.activate()  # a lower action publishing
    runner = ActionRunner(stop, lambda level, text: None)  # its thread is not started: the queue fills
    ctx = Context(1, 3)
    runner.claim()
    runner.submit("start", ctx)
    runner.submit("release", ctx)
    assert arb.owner("/cmd") is stop.seat and list(k for k, _ in runner._queue) == ["start", "release"]
    runner._compact()  # as when the queue is over MAX_PENDING
    assert list(runner._queue) == [] and unclaims == ["stop"]
    assert arb.owner("/cmd") is crawl.seat  # the lower action publishes again
    # a pair dropped while an earlier start ran and its release is queued: that release frees the seat
    runner._queue = collections.deque([("release", Context(2, 3)), ("start", ctx), ("release", ctx)])
    runner._compact()
    assert [k for k, _ in runner._queue] == ["release"] and unclaims == ["stop"]
