"""A service that never answers leaves at most one abandoned call (one thread) per action behind,
however often the action is tried: while it has not returned, a start fails at once saying so and a
hold is skipped (not another failure); once it returns the service is called again."""
import threading
import time

import pytest

pytest.importorskip("rospy")
pytest.importorskip("std_srvs.srv")

from rubass.actions.base import Context  # noqa: E402
from rubass.actions.runner import ActionRunner, Skipped  # noqa: E402
from rubass.lang.library import ActionDef  # noqa: E402
from rubass.ros.actions.service import ServicePlugin  # noqa: E402

CTX = Context(1, 3)


class HangingProxy:
    """A ServiceProxy whose service is advertised but whose handler sleeps until `go` is set."""

    resolved_name = "/brake"

    def __init__(self):
        self.go = threading.Event()
        self.calls = 0

    def wait_for_service(self, timeout):
        pass

    def call(self, request):
        self.calls += 1
        self.go.wait(60)
        return "ok"

    def close(self):
        pass


def brake(call_on=("start", "hold"), timeout=1.0):
    p = ServicePlugin(ActionDef("brake", "service", {"service": "/brake", "type": "std_srvs/Trigger",
                                                      "timeout": timeout, "call_on": list(call_on)}))
    p.setup()
    p.proxy = HangingProxy()
    p._advertised = lambda: True  # no master here: the service is known, it just never answers
    return p


def workers():
    return [t for t in threading.enumerate() if t.name == "rubass-service-brake"]


def test_a_hung_call_is_not_followed_by_another_thread_until_it_returns():
    p = brake()
    try:
        with pytest.raises(TimeoutError, match=r"service /brake did not answer within 1 s"):
            p.start(CTX)
        t0 = time.monotonic()
        with pytest.raises(TimeoutError, match=r"the previous call to /brake has not returned after \d+\.\d s"):
            p.start(CTX)
        assert time.monotonic() - t0 < 0.5, "fails at once, not after another timeout (1 s)"
        with pytest.raises(Skipped, match="the previous call to /brake has not returned"):
            p.hold(CTX)
        assert p.proxy.calls == 1 and len(workers()) == 1
        p.proxy.go.set()  # the service answers at last
        end = time.monotonic() + 5
        while workers() and time.monotonic() < end:
            time.sleep(0.01)
        p.start(CTX)  # called again, and it answers now
        assert p.proxy.calls == 2
    finally:
        p.proxy.go.set()


def test_a_runner_trying_a_hung_service_for_seconds_keeps_one_thread_and_counts_few_failures():
    """The acceptance repro: call_on [start, hold], timeout 0.3 s, the engine's holds at 50 Hz; the
    monitor grew one thread per attempt (18 -> 56 in 50 s)."""
    p = brake(timeout=0.3)
    r = ActionRunner(p, lambda level, text: None)
    r.start_thread()
    try:
        before = threading.active_count()
        r.submit("start", CTX)
        end = time.monotonic() + 2.5
        most = 0
        while time.monotonic() < end:
            r.submit("hold", CTX)
            most = max(most, len(workers()))
            time.sleep(0.02)
        assert most == 1, f"{most} abandoned calls in flight at once"
        assert p.proxy.calls == 1
        assert threading.active_count() <= before + 1
        # the timed-out start, then its retries (0.05, 0.1, 0.2, 0.5, 1 s): not one per hold
        assert 1 <= r.stats.failures <= 8, r.stats.failures
        assert r.stats.failing == "start"
        assert "/brake" in r.stats.last_error
    finally:
        p.proxy.go.set()
        r.stop()


def test_a_reload_that_rebuilds_the_action_does_not_start_a_second_abandoned_call():
    """Re-sweep finding: every reload that changed the action (its timeout 0.3 s <-> 0.4 s) built a new
    plugin with no memory of the hung call, and started another: 8 reloads, 8 more threads."""
    from rubass.ros.actions import service
    end = time.monotonic() + 5
    while workers() and time.monotonic() < end:  # the tests above answered their hung calls
        time.sleep(0.01)
    service._HUNG.clear()
    first = brake(timeout=0.3)
    try:
        with pytest.raises(TimeoutError, match="did not answer"):
            first.start(CTX)
        for timeout in (0.4, 0.3, 0.4):  # the reloads: a new plugin of the same action each time
            again = brake(timeout=timeout)
            again.proxy = first.proxy
            with pytest.raises(TimeoutError, match="the previous call to /brake has not returned"):
                again.start(CTX)
        assert first.proxy.calls == 1 and len(workers()) == 1
    finally:
        first.proxy.go.set()
        end = time.monotonic() + 5
        while workers() and time.monotonic() < end:
            time.sleep(0.01)
