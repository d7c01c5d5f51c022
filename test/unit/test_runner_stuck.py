"""A plugin call that never returns (a custom plugin whose start hangs) is reported: logged once (then
rate-limited), counted, the action failing (/diagnostics: ACTION FAILING) while it is stuck, and
resolved when the call returns. The watchdog needs nothing from the stuck thread."""
import re
import threading
import time

import pytest

from rubass.actions import runner as runner_mod
from rubass.actions.base import ActionPlugin, Context
from rubass.actions.runner import ActionRunner
from rubass.actions.status import RESOLVED
from rubass.lang.library import ActionDef

CTX = Context(1, 3)


class Hang(ActionPlugin):
    """start (or periodic) blocks until `go` is set; holds and releases return at once."""

    def __init__(self, period=None):
        super().__init__(ActionDef("hang", "badplug:Hang", {}))
        self.period = period
        self.go = threading.Event()
        self.calls = []

    def start(self, ctx):
        self.calls.append("start")
        self.go.wait(30)

    def release(self, ctx):
        self.calls.append("release")

    def periodic(self):
        self.calls.append("periodic")
        self.go.wait(30)


def wait_for(cond, seconds=5.0):
    end = time.monotonic() + seconds
    while not cond() and time.monotonic() < end:
        time.sleep(0.01)
    return cond()


@pytest.fixture
def logs():
    return []


def make(plugin, logs):
    r = ActionRunner(plugin, lambda level, text: logs.append((level, text)))
    r.start_thread()
    return r


def test_stuck_is_decided_by_the_time_of_the_call_in_progress_without_its_thread(logs):
    p = Hang()
    r = make(p, logs)
    runner_mod._WATCHDOG.discard(r)  # only this test's calls of stuck(), at the times it chooses
    try:
        r.submit("start", CTX)
        assert wait_for(lambda: p.calls == ["start"])
        t0 = time.monotonic()
        assert r.stuck(t0) is None and not r.stats.failing, "not yet: it has run for less than 2 s"
        text = r.stuck(t0 + runner_mod.STUCK_AFTER + 0.5)
        assert text is not None and re.fullmatch(r"start has not returned for \d+\.\d s: the action is stuck", text)
        assert r.stats.failing == "start" and r.stats.last_error == text
        assert r.stats.failures == 1
        errors = [t for level, t in logs if level == "error"]
        assert errors == [f"action 'hang' {text}"]
        r.stuck(t0 + runner_mod.STUCK_AFTER + 1.0)
        assert r.stats.failures == 1, "one stuck call is one failure, however long it hangs"
        assert len([t for level, t in logs if level == "error"]) == 1, "logged again only every 5 s"
        r.stuck(t0 + runner_mod.STUCK_AFTER + 0.5 + runner_mod.LOG_EVERY)
        assert len([t for level, t in logs if level == "error"]) == 2
        p.go.set()  # the call returns at last: resolved
        assert wait_for(lambda: not r.stats.failing)
        assert r.stats.last_error.startswith(RESOLVED) and "the action is stuck" in r.stats.last_error
        assert r.stuck(time.monotonic() + 100) is None, "nothing in progress any more"
    finally:
        p.go.set()
        r.stop()


def test_the_watchdog_reports_a_hanging_start_on_its_own_and_the_release_then_runs(logs, monkeypatch):
    monkeypatch.setattr(runner_mod, "STUCK_AFTER", 0.3)
    p = Hang()
    r = make(p, logs)
    try:
        r.submit("start", CTX)
        assert wait_for(lambda: r.stats.failing == "start"), "the watchdog thread found it stuck"
        assert "the action is stuck" in r.stats.last_error
        assert any(level == "error" and "action 'hang' start has not returned for" in t for level, t in logs)
        r.submit("release", CTX)
        time.sleep(0.3)
        assert r.stats.failing == "start", "still stuck: still failing"
        p.go.set()
        assert wait_for(lambda: p.calls == ["start", "release"])
        assert wait_for(lambda: not r.stats.failing)
        assert any(level == "info" and "action 'hang' start returned (it was stuck)" in t for level, t in logs)
        assert r.stats.last_error.startswith(RESOLVED) and "has not returned" in r.stats.last_error
    finally:
        p.go.set()
        r.stop()


@pytest.mark.parametrize("ends", ["skipped", "returns"])
def test_a_stuck_call_that_ends_gives_back_the_failing_state_it_found(logs, monkeypatch, ends):
    """Review finding: a stuck call that ended by Skipped left ACTION FAILING for good; one that
    returned erased another failure of the action (a limit's bad input) with its own."""
    monkeypatch.setattr(runner_mod, "STUCK_AFTER", 0.3)

    class Hold(Hang):
        def start(self, ctx):
            self.calls.append("start")
            self.go.wait(30)
            if ends == "skipped":
                raise runner_mod.Skipped("board away")

    p = Hold()
    r = make(p, logs)
    try:
        r.stats.failing, r.stats.last_error = "input", "input: /cmd_vel carries std_msgs/String"
        r.submit("start", CTX)
        assert wait_for(lambda: r.stats.failing == "start")
        p.go.set()
        assert wait_for(lambda: r.stats.failing != "start")
        assert (r.stats.failing, r.stats.last_error) == ("input", "input: /cmd_vel carries std_msgs/String")
    finally:
        p.go.set()
        r.stop()


def test_a_hanging_periodic_is_reported_too(logs, monkeypatch):
    monkeypatch.setattr(runner_mod, "STUCK_AFTER", 0.3)
    p = Hang(period=0.05)
    r = make(p, logs)
    try:
        assert wait_for(lambda: r.stats.failing == "periodic")
        p.go.set()
        assert wait_for(lambda: not r.stats.failing)
    finally:
        p.go.set()
        r.stop()


def test_a_plugin_that_may_block_for_its_own_timeout_gets_that_much_longer(logs):
    p = Hang()
    p.call_timeout = 5.0  # a service action with `timeout: 5 s`
    r = make(p, logs)
    try:
        r.submit("start", CTX)
        assert wait_for(lambda: p.calls == ["start"])
        t0 = time.monotonic()
        assert r.stuck_after == runner_mod.STUCK_AFTER + 5.0
        assert r.stuck(t0 + 6.0) is None
        assert r.stuck(t0 + 7.5) is not None
    finally:
        p.go.set()
        r.stop()
