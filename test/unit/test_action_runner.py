"""The action runner with a fake plugin: order, reference counting, coalescing, retries."""
import threading
import time

from rubass.lang.library import ActionDef
from rubass.actions.base import ActionPlugin, Context
from rubass.actions.runner import ActionRunner


class Fake(ActionPlugin):
    def __init__(self, fail_starts=0, slow=0.0, per_behaviour=False):
        super().__init__(ActionDef("fake", "fake:Fake", {}))
        self.calls = []
        self.fail_starts = fail_starts
        self.slow = slow
        self.per_behaviour = per_behaviour
        self.done = threading.Event()

    def start(self, ctx):
        time.sleep(self.slow)
        if self.fail_starts:
            self.fail_starts -= 1
            raise IOError("board away")
        self.calls.append(("start", ctx.behaviour))

    def hold(self, ctx):
        time.sleep(self.slow)
        self.calls.append(("hold", ctx.behaviour))

    def release(self, ctx):
        self.calls.append(("release", ctx.behaviour))
        self.done.set()


def runner(plugin):
    logs = []
    r = ActionRunner(plugin, lambda level, text: logs.append((level, text)))
    r.start_thread()
    return r, logs


def wait_for(cond, timeout=3.0):
    end = time.monotonic() + timeout
    while not cond() and time.monotonic() < end:
        time.sleep(0.005)
    return cond()


def test_reference_counted_across_behaviours():
    p = Fake()
    r, _ = runner(p)
    r.submit("start", Context(1, 10))
    r.submit("start", Context(2, 11))
    r.submit("release", Context(1, 10))
    r.submit("release", Context(2, 11))
    assert wait_for(p.done.is_set)
    r.stop()
    assert p.calls == [("start", 1), ("release", 2)]


def test_per_behaviour_plugins_see_every_phase():
    p = Fake(per_behaviour=True)
    r, _ = runner(p)
    for kind, b in (("start", 1), ("start", 2), ("release", 1), ("release", 2)):
        r.submit(kind, Context(b, 0))
    assert wait_for(lambda: len(p.calls) == 4)
    r.stop()
    assert p.calls == [("start", 1), ("start", 2), ("release", 1), ("release", 2)]


def test_failing_start_is_retried_and_logged_once():
    p = Fake(fail_starts=3)
    r, logs = runner(p)
    r.submit("start", Context(1, 0))
    assert wait_for(lambda: ("start", 1) in p.calls)
    r.stop()
    errors = [text for level, text in logs if level == "error"]
    assert r.stats.failures == 3 and len(errors) == 1 and "board away" in errors[0]
    assert logs[1:] == [("info", "action 'fake' start succeeded after failing (start: OSError: board away)")]


def test_start_superseded_by_release_is_not_retried_forever():
    p = Fake(fail_starts=1000)
    r, _ = runner(p)
    r.submit("start", Context(1, 0))
    time.sleep(0.1)
    r.submit("release", Context(1, 0))
    assert wait_for(p.done.is_set)
    failures = r.stats.failures
    time.sleep(0.3)
    r.stop()
    assert p.calls == [("release", 1)] and r.stats.failures == failures


def test_slow_plugin_never_blocks_submit_and_holds_coalesce():
    p = Fake(slow=0.2)
    r, _ = runner(p)
    t0 = time.monotonic()
    r.submit("start", Context(1, 0))
    for _ in range(100):
        r.submit("hold", Context(1, 0))
    assert time.monotonic() - t0 < 0.05
    time.sleep(0.5)
    r.stop()
    assert p.calls.count(("hold", 1)) <= 2


def test_queue_stays_bounded_when_a_stuck_plugin_meets_a_flapping_condition():
    from rubass.actions import runner as runner_mod

    p = Fake(slow=5.0, per_behaviour=True)
    r, _ = runner(p)
    for _ in range(3000):
        r.submit("start", Context(1, 0))
        r.submit("release", Context(1, 0))
    assert len(r._queue) <= runner_mod.MAX_PENDING + 1
    assert r.stats.extra["dropped pairs"] > 0


def test_periodic_work_goes_on_while_a_failing_start_is_retried_and_a_release_cuts_the_wait():
    p = Fake(fail_starts=100)
    p.period = 0.02
    ticks = []
    p.periodic = lambda: ticks.append(time.monotonic())
    r, logs = runner(p)
    r.submit("start", Context(1, 0))
    time.sleep(1.5)  # the retries back off to 1 s apart by now
    assert len([t for t in ticks if t > ticks[0] + 1.0]) > 10, "a publish keeps its rate while start fails"
    t0 = time.monotonic()
    r.submit("release", Context(1, 0))
    assert p.done.wait(2.0) and time.monotonic() - t0 < 0.2, "the release did not wait out the 1 s backoff"
    r.stop()
