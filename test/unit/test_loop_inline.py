"""The engine loop's inline mode (issue 17): a message is handled on the thread that submits it
when the engine is free, in queue order otherwise; deadlines still wake the loop's own thread."""
import os
import threading
import time

from rubass.engine import Engine
from rubass.engine.loop import EngineLoop, Message
from rubass.lang import check_text

from conftest import ROOT

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")
SPEC = "entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { warn; }\n"


def make(body=SPEC, clock=None, **kw):
    spec = check_text("action primitive stop, warn;\n" + body, os.path.join(ROOT, "x.rbs"), [LIB])
    got = []  # (event kind, cause, thread)
    clock = clock or (lambda: 0.0)

    def handler(events, cause):
        got.extend((e.kind, cause, threading.current_thread()) for e in events if e.kind in ("start", "release"))
    loop = EngineLoop(Engine(spec, clock()), clock, 50.0, handler, inline=True, **kw)
    return loop, got


def test_a_message_is_handled_on_the_submitting_thread_at_once():
    loop, got = make()
    m = Message("/x", 1.0, {"data": 2})
    assert loop.submit(m)
    assert got == [("start", m, threading.current_thread())]  # no step() of the loop needed
    assert loop.inbox.empty() and loop.queued_bytes == 0


def test_messages_queued_while_the_engine_is_busy_are_handled_in_order_by_the_next_thread():
    loop, got = make()
    msgs = [Message("/x", 1.0 + i, {"data": 2 if i % 2 == 0 else 0}, size=10) for i in range(5)]
    with loop._engine_lock:  # another thread is evaluating
        assert all(loop.submit(m) for m in msgs[:4])
        assert got == [] and loop.inbox.qsize() == 4 and loop.queued_bytes == 40
    loop.submit(msgs[4])  # finds the queue non-empty: queues, then handles all five in order
    assert [(k, c) for k, c, _ in got] == [("start", msgs[0]), ("release", msgs[1]), ("start", msgs[2]),
                                           ("release", msgs[3]), ("start", msgs[4])]
    assert loop.inbox.empty() and loop.queued_bytes == 0


def test_a_full_queue_while_busy_still_conflates_and_counts_drops():
    loop, got = make(max_queue=2)
    with loop._engine_lock:
        results = [loop.submit(Message("/x", 1.0 + i, {"data": 2 if i == 3 else 0})) for i in range(4)]
    assert results == [True, True, False, False] and loop.dropped == 2
    loop.submit(Message("/y", 9.0))  # the next submit handles the queue, then the newest of /x
    assert [k for k, _, _ in got] == ["start"] and got[0][1].time == 4.0  # the newest /x was never lost


def test_an_error_while_handling_inline_goes_to_on_error_and_the_next_message_is_handled():
    errors = []
    loop, got = make(on_error=errors.append)
    real = loop.engine.on_message
    calls = []

    def flaky(topic, now, msg):
        calls.append(now)
        if len(calls) == 1:
            raise RuntimeError("bug")
        return real(topic, now, msg)
    loop.engine.on_message = flaky
    loop.submit(Message("/x", 1.0, {"data": 2}))
    loop.submit(Message("/x", 2.0, {"data": 2}))
    assert [str(e) for e in errors] == ["bug"] and [k for k, _, _ in got] == ["start"]
    assert not loop._engine_lock.locked()


def test_a_deadline_set_inline_wakes_the_loops_thread_before_its_next_tick():
    spec_body = "entity a { rules: r: (topic /x.data > 1) for 0.05 s; }\nif (a.r) then { warn; }\n"
    spec = check_text("action primitive stop, warn;\n" + spec_body, os.path.join(ROOT, "x.rbs"), [LIB])
    got = []
    loop = EngineLoop(Engine(spec, time.monotonic()), time.monotonic, 0.2,  # ticks 5 s apart
                      lambda events, cause: got.extend(e for e in events if e.kind == "start"), inline=True)
    thread = threading.Thread(target=loop.run, daemon=True)
    thread.start()
    try:
        time.sleep(0.05)  # the loop's thread now sleeps until its next tick
        t0 = time.monotonic()
        loop.submit(Message("/x", t0, {"data": 2}))
        end = time.monotonic() + 3.0
        while not got and time.monotonic() < end:
            time.sleep(0.005)
    finally:
        loop.stop()
        thread.join(2)
    assert len(got) == 1 and got[0].time == t0 + 0.05  # fired by the deadline, long before the tick


def test_call_works_in_inline_mode():
    loop, _ = make()
    thread = threading.Thread(target=loop.run, daemon=True)
    thread.start()
    try:
        loop.submit(Message("/x", 1.0, {"data": 2}))
        assert loop.call(lambda engine: engine.rule_value("a.r")) is True
    finally:
        loop.stop()
        thread.join(2)
    assert not thread.is_alive()
