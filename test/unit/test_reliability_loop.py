"""Issue 13 (3): with the engine's queue full, the newest message of each topic is kept
(conflation): a violation that arrives last after a burst of harmless messages is acted on."""
import os

from rubass.engine import Engine
from rubass.engine.loop import EngineLoop, Message
from rubass.lang import check_text

from conftest import ROOT, Clock

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")


def make(body, max_queue=10):
    spec = check_text("action primitive stop, warn;\n" + body, os.path.join(ROOT, "x.rbs"), [LIB])
    got = []
    clock = Clock()
    loop = EngineLoop(Engine(spec, clock.t), clock, 50.0, lambda events, cause: got.extend(events),
                      max_queue=max_queue)
    return loop, clock, got


def drain(loop, clock, steps=200):
    for _ in range(steps):
        clock.t += 0.0001
        loop.step(max_wait=0)


def test_a_violation_after_a_burst_that_overflows_the_queue_is_still_acted_on():
    loop, clock, got = make("entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { stop; }\n")
    for i in range(100):  # the engine's thread is busy: nothing is taken from the queue
        clock.t += 0.001
        loop.submit(Message("/x", clock.t, {"data": 0.0}))
    clock.t += 0.001
    assert not loop.submit(Message("/x", clock.t, {"data": 5.0}))  # the violation, last, overflows
    drain(loop, clock)
    assert [e.kind for e in got if e.kind in ("start", "release")] == ["start"], got
    assert loop.engine.rule_value("a.r") is True, "older queued messages did not overwrite the newest value"
    assert loop.dropped == 91 and loop.dropped_by_topic == {"/x": 91}


def test_the_newest_of_each_topic_is_kept_and_other_topics_are_untouched():
    loop, clock, got = make("entity a { rules: r: topic /x.data > 1; q: topic /y.data > 1; }\n"
                            "if (a.r) then { stop; }\nif (a.q) then { warn; }\n", max_queue=10)
    for i in range(10):
        clock.t += 0.001
        loop.submit(Message("/x", clock.t, {"data": 0.0}))
    for v in (7.0, 0.0, 9.0):  # /y overflows: only its newest (9) is kept
        clock.t += 0.001
        loop.submit(Message("/y", clock.t, {"data": v}))
    drain(loop, clock)
    assert loop.engine.rule_value("a.q") is True and loop.engine.rule_value("a.r") is False
    assert loop.dropped_by_topic == {"/y": 3}
    # once the queue has drained, normal order again: a later message of /y is not skipped
    clock.t += 0.001
    loop.submit(Message("/y", clock.t, {"data": 0.0}))
    drain(loop, clock, 5)
    assert loop.engine.rule_value("a.q") is False


def test_a_clock_that_jumps_back_restarts_windows_and_a_persisting_violation_is_still_stopped():
    loop, clock, got = make("entity a { rules: r: (topic /x.data > 1) for 1 s; }\nif (a.r) then { stop; }\n")
    for _ in range(5):  # 0.5 s of the violation at 100 s
        clock.t += 0.1
        loop.submit(Message("/x", clock.t, {"data": 5.0}))
        loop.step(max_wait=0)
    clock.t = 10.0  # the simulator is reset
    jump = clock.t
    for _ in range(15):
        clock.t += 0.1
        loop.submit(Message("/x", clock.t, {"data": 5.0}))
        loop.step(max_wait=0)
        loop.step(max_wait=0)
    starts = [e for e in got if e.kind == "start"]
    assert loop.clock_jumps == 1
    assert starts and jump < starts[0].time <= jump + 1.1 + 1e-9, starts  # not at 101 s of the old timeline


def test_clock_jump_hook_holds_what_was_active_until_the_rebuilt_engine_takes_it_over():
    from rubass.ros.clockjump import ClockJump, horizon

    loop, clock, got = make("entity a { rules: r: (topic /x.data > 1) for 1 s; }\nif (a.r) then { warn; }\n")
    released = []

    class Dispatcher:
        def __init__(self):
            self.orphans = []

        def keys_of(self, spec):
            return {b.index: ("k", b.index) for b in spec.behaviours}

        def release(self, b, key, now):
            released.append((b.index, now))

        def report_event(self, e, b, rules, cause):
            pass

        def handle(self, engine, events, cause):
            pass

    assert horizon(loop.engine.spec) == 1.5
    hook = ClockJump(Dispatcher(), lambda level, text: None, lambda engine: None)
    loop.on_clock_jump = hook
    for _ in range(12):
        clock.t += 0.1
        loop.submit(Message("/x", clock.t, {"data": 5.0}))
        loop.step(max_wait=0)
    assert loop.engine.active_behaviours() == [1]
    clock.t = 10.0
    loop.submit(Message("/x", clock.t, {"data": 0.0}))  # the violation is gone after the reset
    loop.step(max_wait=0)
    assert len(hook.carried) == 1 and not released
    clock.t = 11.0
    hook.check(loop.engine, clock.t)
    assert not released, "held while a persisting violation could still be re-established"
    clock.t = 11.6
    hook.check(loop.engine, clock.t)
    assert released == [(1, 11.6)] and not hook.carried


def test_after_a_clock_jump_a_latched_behaviour_is_held_until_reset_like_after_a_reload():
    from rubass.ros.clockjump import ClockJump

    loop, clock, got = make("entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { stop; }\n")

    class Dispatcher:
        def __init__(self):
            self.orphans = []

        def keys_of(self, spec):
            return {b.index: ("k", b.index) for b in spec.behaviours}

        def handle(self, engine, events, cause):
            pass

    d = Dispatcher()
    loop.on_clock_jump = ClockJump(d, lambda level, text: None, lambda engine: None)
    clock.t += 0.1
    loop.submit(Message("/x", clock.t, {"data": 5.0}))
    loop.step(max_wait=0)
    clock.t = 10.0
    loop.step(max_wait=0)
    assert [(b.index, key) for b, key in d.orphans] == [(1, ("k", 1))]


def test_the_clock_jump_horizon_covers_every_window_of_time_in_v2():
    from rubass.ros.clockjump import horizon

    loop, _, _ = make("entity a { rules:\n"
                      "  s: age(topic /scan) > 2 s;\n"
                      "  f: frequency(topic /scan, 3 s) < 5 Hz;\n"
                      "  w: topic /b.p within 4 s;\n"
                      "  t: stamp_age(topic /imu) + 0.1 s > 2.5 s;\n"
                      "}\nif (a.s or a.f or a.w or a.t) then { warn; }\n")
    assert horizon(loop.engine.spec) == 4.5  # the within window, + 0.5 s


def test_after_a_clock_jump_active_of_a_held_action_stays_true_until_reset():
    from rubass.ros.clockjump import ClockJump

    loop, clock, got = make("entity a { rules: r: topic /x.data > 1; m: topic /y.data > 0; }\n"
                            "if (a.r) then { stop; }\nif (active(stop) and a.m) then { warn; }\n")

    class Dispatcher:
        orphans = []

        def keys_of(self, spec):
            return {b.index: ("k", b.index) for b in spec.behaviours}

    loop.on_clock_jump = ClockJump(Dispatcher(), lambda level, text: None, lambda engine: None)
    clock.t += 0.1
    loop.submit(Message("/x", clock.t, {"data": 5.0}))
    loop.step(max_wait=0)
    clock.t = 10.0  # back in time: the engine is rebuilt
    loop.submit(Message("/x", clock.t, {"data": 0.0}))
    loop.step(max_wait=0)
    assert loop.engine.active_actions() == {"stop": ("behaviour 1 (latched before a clock jump)",)}
    clock.t = 10.5
    loop.submit(Message("/y", clock.t, {"data": 1.0}))  # the ladder still sees the stop
    loop.step(max_wait=0)
    assert 2 in loop.engine.active_behaviours()
    loop.engine.reset(clock.t)
    assert loop.engine.active_actions().get("stop") is None


def test_a_message_on_the_new_timeline_before_the_loop_noticed_the_jump_starts_nothing():
    """Acceptance finding (sim time, /clock reset from 112 s to 10 s): the first /odom message of the
    new timeline was evaluated inline, by the old engine, before the engine's thread saw the jump:
    age(/odom) read 108.98 s and `age(topic /odom) > 0.5 s` started a stop (released 1.5 s later).
    A message whose time is behind the loop's clock, with the clock itself gone back, is the jump."""
    spec = check_text("action primitive stop, warn;\nentity o { rules: silent: age(topic /odom) > 0.5 s; }\n"
                      "if (o.silent) then { stop; }\n", os.path.join(ROOT, "x.rbs"), [LIB])
    got = []
    clock = Clock()
    clock.t = 100.0
    loop = EngineLoop(Engine(spec, clock.t), clock, 50.0, lambda events, cause: got.extend(events), inline=True)
    for _ in range(40):  # /odom at 20 Hz on the old timeline
        clock.t += 0.05
        loop.submit(Message("/odom", clock.t, {"data": 1.0}))
        loop.step(max_wait=0)
    assert [e.kind for e in got if e.kind in ("start", "release")] == []
    clock.t = 10.0  # the simulator is reset; the next message comes before the engine's thread wakes
    clock.t += 0.05
    loop.submit(Message("/odom", clock.t, {"data": 1.0}))
    for _ in range(10):
        clock.t += 0.05
        loop.submit(Message("/odom", clock.t, {"data": 1.0}))
        loop.step(max_wait=0)
    assert loop.clock_jumps == 1
    assert [e.kind for e in got if e.kind in ("start", "release")] == [], got
