"""The monitor's swap of a reloaded spec (rubass/ros/reloading.py) with the engine's real objects
and fakes for ROS: nothing that fell due before the swap is lost."""
import os

import pytest

pytest.importorskip("rospy")

from rubass.engine import Engine  # noqa: E402
from rubass.lang import check_text  # noqa: E402
from rubass.ros import reloading  # noqa: E402

from conftest import ROOT  # noqa: E402

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")
SPEC = "action primitive warn;\nentity a { rules: r: (topic /x.data > 1) for 1 s; }\nif (a.r) then { warn; }\n"


class FakeMonitor(reloading.Reloading):
    def __init__(self, engine):
        self.dispatched = []
        self.loop = type("Loop", (), {"engine": engine})()
        self.dispatcher = type("D", (), {"orphans": [], "runners": {}, "keys_of": lambda s, spec: {},
                                         "release": lambda *a: None})()
        self.keeper = type("K", (), {"save": lambda *a: None})()

    def _on_events(self, events, cause):
        self.dispatched += [(e.kind, e.time, cause) for e in events if e.kind != "rule"]

    def _fail_safes(self):
        return []


def test_a_deadline_due_at_the_reload_is_dispatched_under_the_old_rules(monkeypatch):
    spec = check_text(SPEC, os.path.join(ROOT, "s.rbs"), [LIB])
    old = Engine(spec, 0.0)
    old.evaluate_all(0.0)
    old.on_message("/x", 0.5, {"data": 5.0})  # the `for` falls due at 1.5, before the swap at 2.0
    monitor = FakeMonitor(old)
    monkeypatch.setattr(reloading, "ros_now", lambda: 2.0)
    new = Engine(check_text(SPEC, os.path.join(ROOT, "s.rbs"), [LIB]), 2.0)
    monitor._swap(old, new, new.spec, {})
    assert ("start", 1.5, "deadline") in monitor.dispatched  # the stop started: it was not swallowed
    assert new.active_behaviours() == [1] and monitor.loop.engine is new


def test_a_named_active_behaviour_whose_rule_changed_is_released_by_its_runner_after_a_reload():
    from rubass.actions.dispatch import Dispatcher

    text = "action primitive warn;\nentity a {{ rules: r: topic /x.data > {}; }}\noverspeed: if (a.r) then {{ warn; }}\n"
    old_spec = check_text(text.format(1), os.path.join(ROOT, "s.rbs"), [LIB])
    new_spec = check_text(text.format(2), os.path.join(ROOT, "s.rbs"), [LIB])
    old = Engine(old_spec, 0.0)
    old.on_message("/x", 1.0, {"data": 5.0})
    new = Engine(new_spec, 2.0)
    new.adopt(old, 2.0)
    assert new.active_behaviours() == [1]  # carried by name: no second start
    # the dispatcher keys it as the engine carries it, so the release reaches the runner that holds it
    assert Dispatcher.keys(old_spec.behaviours)[1] == Dispatcher.keys(new_spec.behaviours)[1]
    assert [e.kind for e in new.on_message("/x", 3.0, {"data": 0.0}) if e.kind != "rule"] == ["release"]
    changed = check_text(text.format(2).replace("{ warn; }", '{ warn("other"); }'), os.path.join(ROOT, "s.rbs"), [LIB])
    assert Dispatcher.keys(changed.behaviours)[1] != Dispatcher.keys(new_spec.behaviours)[1]  # other actions


def test_sighups_are_served_by_one_thread_that_coalesces_a_storm_and_outlives_a_failed_reload(monkeypatch):
    import threading
    import time

    monitor = FakeMonitor(None)
    monitor._reload_wanted, monitor.coalesced = threading.Event(), 0
    calls, logged, gate = [], [], threading.Event()

    def reload(reason):
        calls.append((reason, threading.current_thread().name))
        if len(calls) == 1:
            gate.wait(10)
            raise RuntimeError("a bug in a reload")
        return True, "reloaded"

    def wait_for(n):
        end = time.monotonic() + 10
        while len(calls) < n and time.monotonic() < end:
            time.sleep(0.01)
        return len(calls)

    monitor.reload = reload
    monkeypatch.setattr(reloading.rospy, "logerr", lambda fmt, *args: logged.append(fmt % args))
    worker = threading.Thread(target=monitor.reload_thread, name="rubass-reload", daemon=True)
    worker.start()
    before = threading.active_count()
    monitor.request_reload()
    assert wait_for(1) == 1
    for _ in range(50):  # while the first reload runs: one waits behind it, 49 join that one
        monitor.request_reload()
    assert monitor.coalesced == 49 and threading.active_count() == before, "a SIGHUP starts no thread"
    gate.set()
    assert wait_for(2) == 2
    time.sleep(0.2)
    assert len(calls) == 2 and worker.is_alive()
    assert logged == ["rubass: reload (SIGHUP) failed: RuntimeError: a bug in a reload"]
    monitor.request_reload()  # the thread serves the next SIGHUP
    assert wait_for(3) == 3 and calls == [("SIGHUP", "rubass-reload")] * 3


def test_a_reload_asked_while_the_monitor_starts_is_noted_with_what_asked_it():
    """A re-sweep: `~reload` while the spec was read did not exist yet, and one asked while the monitor
    waited for /clock was run on an engine that did not exist. While it starts, a reload is noted (setup
    runs it once it enforces, labelled with what asked it) and reads nothing; once it stops, none runs."""
    import threading

    monitor = FakeMonitor(None)
    monitor._starting, monitor._start_lock, monitor._reload_deferred = True, threading.Lock(), []
    monitor._exit = threading.Event()
    ok, text = monitor.reload("service")
    assert not ok and "still starting" in text and "as soon as it enforces" in text
    monitor.reload("SIGHUP")
    monitor.reload("service")
    assert monitor._reload_deferred == ["service", "SIGHUP"]
    monitor._starting = False
    monitor._exit.set()
    assert monitor.reload("SIGHUP") == (False, "the monitor is stopping")
