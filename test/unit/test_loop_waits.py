"""How long messages wait in the engine's queue (rubass/engine/loop.py, take_waited): a monitor
whose engine cannot keep up drops nothing until its queue is full (100,000 messages: minutes at
some rates) while its rules see the robot, and its stops come, seconds late; that wait is what
starts the overload fail-safe before any drop (a 6,000-rule spec over 20 topics at 100 Hz: stops
4.7 s late at p50, and no fail-safe, before this measure)."""
from test_loop_inline import make

from rubass.engine.loop import Message


class Mono:
    def __init__(self):
        self.t = 100.0

    def __call__(self):
        return self.t


def test_a_message_queued_behind_a_busy_engine_waited_until_it_was_handled():
    mono = Mono()
    loop, got = make(mono=mono)
    with loop._engine_lock:  # the engine's thread is evaluating: these queue
        loop.submit(Message("/x", 1.0, {"data": 0}, arrived=mono()))
        mono.t += 0.3
        loop.submit(Message("/x", 1.3, {"data": 2}, arrived=mono()))
        mono.t += 0.5  # the busy engine frees 0.8 s after the first arrived
    loop._pump()
    assert [k for k, _, _ in got] == ["start"]
    assert abs(loop.take_waited() - 0.8) < 1e-9  # the longest wait: the first message's
    assert loop.take_waited() == 0.0  # since the tick last asked: nothing
    assert abs(loop.take_waited(1) - 0.8) < 1e-9  # the status asks apart from the tick
    assert loop.take_waited(1) == 0.0


def test_a_message_handled_at_once_waited_nothing_and_one_without_arrival_is_not_measured():
    mono = Mono()
    loop, _ = make(mono=mono)
    loop.submit(Message("/x", 1.0, {"data": 0}, arrived=mono() - 5.0))  # the engine free: inline, never queued
    with loop._engine_lock:
        loop.submit(Message("/x", 2.0, {"data": 0}))  # a recording's message: no arrival
    mono.t += 3.0
    loop._pump()
    assert loop.take_waited() == 0.0 and loop.inbox.empty()


def test_the_engines_own_thread_measures_what_it_drains_and_conflated_messages_too():
    mono = Mono()
    loop, got = make(mono=mono, max_queue=2)
    with loop._engine_lock:
        for i in range(4):  # two queue, the newest of the others is kept aside (conflation)
            loop.submit(Message("/x", 1.0 + i, {"data": 2 if i == 3 else 0}, arrived=mono()))
            mono.t += 0.25
    assert loop.dropped == 2
    loop.step(max_wait=0.0)  # the engine's thread: drains, then the newest
    assert [k for k, _, _ in got] == ["start"]
    assert abs(loop.take_waited() - 1.0) < 1e-9  # the first queued, 1 s before the engine took it


def test_a_conflated_message_is_measured_from_its_own_arrival():
    mono = Mono()
    loop, _ = make(mono=mono, max_queue=1)
    with loop._engine_lock:
        loop.submit(Message("/x", 1.0, {"data": 0}, arrived=mono()))  # queued
        loop.submit(Message("/y", 1.1, {"data": 0}, arrived=mono() - 2.0))  # kept aside as /y's newest
    loop.step(max_wait=0.0)
    assert abs(loop.take_waited() - 2.0) < 1e-9


def slowed(loop, clock, cost):
    """Each message takes the engine `cost` seconds of `clock`; returns the handling order."""
    order, real = [], loop.engine.on_message

    def on_message(topic, t, msg):
        clock.t += cost
        order.append("msg")
        return real(topic, t, msg)
    loop.engine.on_message = on_message
    loop.tick_hook = lambda now: order.append("tick")
    return order


def test_a_busy_engine_ticks_between_queued_messages_not_after_a_whole_burst():
    """The tick runs the overload check: after a burst of 256 slow messages (6.5 ms each: 1.7 s) it
    came too late to start the fail-safe while the robot still moved (a live run said 2.73 s late)."""
    clock = Mono()
    clock.t = 0.0
    loop, _ = make(clock=clock)  # ticks every 20 ms from 0
    order = slowed(loop, clock, 0.015)
    with loop._engine_lock:
        for i in range(10):
            loop.submit(Message("/x", i * 0.001, {"data": 0}))
    loop.step(max_wait=0.0)
    assert order == ["msg", "msg", "tick"]  # the second ended past the tick's instant: the tick, then on
    while loop.inbox.queue:
        loop.step(max_wait=0.0)
    assert order.count("msg") == 10 and order.count("tick") >= 6


def test_a_submitting_thread_that_drains_leaves_the_rest_to_the_engines_thread_at_the_tick():
    clock = Mono()
    clock.t = 0.0
    loop, _ = make(clock=clock)
    order = slowed(loop, clock, 0.015)
    with loop._engine_lock:
        for i in range(10):
            loop.submit(Message("/x", i * 0.001, {"data": 0}))
    loop._wake.clear()
    loop._pump()  # as a receiving thread's submit does
    assert order == ["msg", "msg"] and loop.inbox.qsize() == 8 and loop._wake.is_set()
