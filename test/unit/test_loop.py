"""The engine loop: inputs from other threads, wake-ups at deadlines with no input, calls."""
import os
import threading
import time

from rubass.engine import Engine
from rubass.engine.loop import EngineLoop, Message
from rubass.lang import check_text

from conftest import ROOT

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")


def make(spec_body, rate=50.0):
    spec = check_text("action primitive stop, warn;\n" + spec_body, os.path.join(ROOT, "x.rbs"), [LIB])
    got = []
    engine = Engine(spec, time.monotonic())
    loop = EngineLoop(engine, time.monotonic, rate, lambda events, cause: got.extend(events))
    thread = threading.Thread(target=loop.run, daemon=True)
    thread.start()
    return loop, thread, got


def test_for_fires_at_its_deadline_with_no_further_input():
    loop, thread, got = make("entity a { rules: r: (topic /x.data > 1) for 0.05 s; }\nif (a.r) then { warn; }\n",
                             rate=1.0)  # ticks far apart: only the deadline can wake the loop
    t0 = time.monotonic()
    loop.submit(Message("/x", t0, {"data": 2}))
    deadline = time.monotonic() + 3.0
    while not any(e.kind == "start" for e in got) and time.monotonic() < deadline:
        time.sleep(0.005)
    loop.stop()
    thread.join(2)
    starts = [e for e in got if e.kind == "start"]
    assert len(starts) == 1 and starts[0].time == t0 + 0.05


def test_call_runs_on_the_engine_thread_and_returns_or_raises():
    loop, thread, _ = make("entity a { rules: r: topic /x.data > 1; }\nif (a.r) then { stop; }\n")
    assert loop.call(lambda engine: threading.current_thread() is thread)

    def boom(engine):
        raise ValueError("nope")

    try:
        loop.call(boom)
        raised = None
    except ValueError as exc:
        raised = exc
    loop.stop()
    thread.join(2)
    assert str(raised) == "nope"


def test_full_queue_counts_drops_instead_of_blocking():
    spec = check_text("action primitive warn;\nentity a { rules: r: topic /x.data > 1; }\nif (a.r) then { warn; }\n",
                      os.path.join(ROOT, "x.rbs"), [LIB])
    loop = EngineLoop(Engine(spec, 0.0), lambda: 0.0, 50.0, lambda events, cause: None, max_queue=3)
    assert [loop.submit(Message("/x", 0.0, {"data": 1})) for _ in range(5)] == [True, True, True, False, False]
    assert loop.dropped == 2


def test_the_queue_holds_a_bounded_number_of_message_bytes_and_frees_them_when_handled():
    spec = check_text("action primitive warn;\nentity a { rules: r: max(topic /x.data) > 1; }\n"
                      "if (a.r) then { warn; }\n", os.path.join(ROOT, "x.rbs"), [LIB])
    loop = EngineLoop(Engine(spec, 0.0), lambda: 0.0, 50.0, lambda events, cause: None, max_bytes=20_000_000)
    cloud = Message("/x", 0.0, {"data": b"\x02" * 8_000_000}, size=8_000_000)  # an 8 MB point cloud
    assert [loop.submit(cloud) for _ in range(3)] == [True, True, False]
    assert loop.dropped == 1 and loop.queued_bytes == 16_000_000
    assert loop.submit(Message("/x", 0.0, {"data": b"\x00"}, size=1))  # small ones still fit
    loop.step(max_wait=0.01)
    assert loop.queued_bytes == 8_000_001 and loop.engine.rule_value("a.r") is True
    assert loop.submit(cloud)


def test_ticks_go_on_when_the_clock_jumps_back():
    """Sim time restarting (a looping bag) must not stall ticks, and with them the heartbeat."""
    spec = check_text("action primitive warn;\nentity a { rules: r: topic /x.data > 1; }\nif (a.r) then { warn; }\n",
                      os.path.join(ROOT, "x.rbs"), [LIB])
    now = [100.0]
    ticks = []
    loop = EngineLoop(Engine(spec, 100.0), lambda: now[0], 50.0, lambda events, cause: None,
                      tick_hook=ticks.append)
    now[0] = 100.03
    loop.step(max_wait=0)
    now[0] = 5.0  # back by 95 s
    loop.step(max_wait=0)
    now[0] = 5.03
    loop.step(max_wait=0)
    assert ticks == [100.03, 5.03]


def test_a_stall_resumes_ticking_without_a_burst():
    spec = check_text("action primitive warn;\nentity a { rules: r: topic /x.data > 1; }\nif (a.r) then { warn; }\n",
                      os.path.join(ROOT, "x.rbs"), [LIB])
    now = [0.0]
    ticks = []
    loop = EngineLoop(Engine(spec, 0.0), lambda: now[0], 50.0, lambda events, cause: None, tick_hook=ticks.append)
    now[0] = 1.0  # 50 ticks late
    loop.step(max_wait=0)
    loop.step(max_wait=0)
    assert ticks == [1.0]

