"""~events after a clock jump back: a behaviour that stays active across it gets no second
`start`, and one the rebuilt engine does not take over gets its `release` (starts and releases
stay paired)."""
import os

from rubass.actions.dispatch import Dispatcher
from rubass.engine import Engine
from rubass.engine.loop import EngineLoop, Message
from rubass.lang import check_text
from rubass.ros.clockjump import ClockJump

from conftest import ROOT, Clock

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")


def monitor(body):
    """An engine loop wired as the monitor wires it: the clock-jump hook, then the dispatcher."""
    spec = check_text("action primitive stop, warn;\n" + body, os.path.join(ROOT, "x.rbs"), [LIB])
    clock = Clock()
    reports = []
    dispatcher = Dispatcher({}, reports.append, clock)
    hook = ClockJump(dispatcher, lambda level, text: None, lambda engine: None)

    def on_events(events, cause):
        dispatcher.handle(loop.engine, hook.take_over(loop.engine, events), cause)

    loop = EngineLoop(Engine(spec, clock.t), clock, 50.0, on_events, on_clock_jump=hook)
    return loop, clock, hook, dispatcher, reports


def feed(loop, clock, value, until, step=0.1):
    while clock.t < until - 1e-9:
        clock.t = round(clock.t + step, 6)
        loop.submit(Message("/x", clock.t, {"data": value}))
        loop.step(max_wait=0)


def kinds(reports):
    return [(r["event"], r["behaviour"]) for r in reports]


FOR = "entity a { rules: r: (topic /x.data > 1) for 1 s; }\nif (a.r) then { warn; }\n"


def tick(loop, hook, clock):
    hook.check(loop.engine, clock.t)


def test_a_behaviour_active_across_the_jump_and_true_again_gets_no_second_start():
    loop, clock, hook, dispatcher, reports = monitor(FOR)
    feed(loop, clock, 5.0, 101.3)
    assert kinds(reports) == [("start", 1)]
    clock.t = 5.0  # a simulator reset; the violation persists
    feed(loop, clock, 5.0, 7.0)
    tick(loop, hook, clock)
    assert loop.clock_jumps == 1 and loop.engine.active_behaviours() == [1]
    assert kinds(reports) == [("start", 1)], "no second start for a behaviour that stayed active"
    assert not hook.carried, "the rebuilt engine owns it now"
    feed(loop, clock, 0.0, 7.5)
    tick(loop, hook, clock)
    assert kinds(reports) == [("start", 1), ("release", 1)]


def test_a_carried_behaviour_the_rebuilt_engine_does_not_take_over_is_reported_released():
    loop, clock, hook, dispatcher, reports = monitor(FOR)
    feed(loop, clock, 5.0, 101.3)
    clock.t = 5.0
    feed(loop, clock, 0.0, 6.0)  # the violation is gone after the reset
    tick(loop, hook, clock)
    assert kinds(reports) == [("start", 1)], "held while it could be re-established (horizon 1.5 s)"
    feed(loop, clock, 0.0, 6.6)
    tick(loop, hook, clock)
    assert kinds(reports) == [("start", 1), ("release", 1)]
    assert not hook.carried


def test_a_latched_behaviour_true_again_after_the_jump_gets_no_second_start_and_one_release():
    loop, clock, hook, dispatcher, reports = monitor(
        "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { stop; }\n")
    feed(loop, clock, 5.0, 100.3)
    clock.t = 5.0
    feed(loop, clock, 5.0, 6.0)
    assert kinds(reports) == [("start", 1)]
    assert dispatcher.orphans == [], "the rebuilt engine holds the latch itself now"
    feed(loop, clock, 0.0, 6.5)
    dispatcher.handle(loop.engine, hook.take_over(loop.engine, loop.engine.reset(clock.t)), "reset")
    assert kinds(reports) == [("start", 1), ("release", 1)]
    assert loop.engine.active_actions() == {}
