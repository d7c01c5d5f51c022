"""An active `publish` whose subscribers have all gone (the base killed, its link cut) fails at
each periodic publication, so /diagnostics shows the stop reaching no one (an acceptance tester's
finding: it stayed OK while the stop went to nobody at its rate), until a publication reaches a
subscriber again; and its publisher writes each subscriber from a thread of its own, so one that
stops reading cannot hold the stop from the others."""
import pytest

pytest.importorskip("rospy")

from test_publish_release_unowned import plugin  # noqa: E402

from rubass.actions.runner import ActionRunner  # noqa: E402
from rubass.ros.actions import publish  # noqa: E402


def active(subscribers):
    p = plugin(mine=True, subscribers=subscribers)
    p.params["rate"], p.name, p.active, p.period = 20.0, "stop", True, 0.05
    return p


def test_a_periodic_publication_that_reached_no_one_is_a_failure():
    p = active(subscribers=0)
    with pytest.raises(IOError, match=r"no node subscribes to /cmd: the message reached no one; it is sent again "
                                      r"at 20 Hz"):
        p.periodic()
    assert len(p.pub.sent) == 1  # still sent: a subscriber that connects meanwhile gets it
    p.pub.subscribers = 1
    p.periodic()  # reaches one: no failure
    assert len(p.pub.sent) == 2


def test_the_failure_is_counted_shown_and_resolved_by_the_next_publication_that_reaches_one():
    p = active(subscribers=0)
    logs = []
    runner = ActionRunner(p, lambda level, text: logs.append((level, text)))
    assert not runner._guard("periodic", p.periodic)
    assert runner.stats.failing == "periodic" and runner.stats.failures == 1
    assert "periodic: OSError: no node subscribes to /cmd: the message reached no one" in runner.stats.last_error
    p.pub.subscribers = 1
    assert runner._guard("periodic", p.periodic)
    assert runner.stats.failing == ""
    p.pub.subscribers = 0
    assert not runner._guard("periodic", p.periodic)
    p.pub.subscribers = 1  # the next activation's start reaches one: that resolves it too
    assert runner._guard("start", lambda: p.start(None))
    assert runner.stats.failing == ""


def test_an_action_publisher_queues_per_subscriber(monkeypatch):
    made = []
    monkeypatch.setattr(publish.rospy, "Publisher", lambda *a, **kw: made.append((a, kw)))
    publish.action_publisher("/stop", object)
    assert made[0][1]["queue_size"] == publish.PER_SUBSCRIBER_QUEUE > 0  # rospy's QueuedConnection per subscriber


def test_closing_waits_for_each_subscribers_thread_to_take_its_messages_but_not_for_a_stuck_one():
    import threading
    import time
    from types import SimpleNamespace

    reading = SimpleNamespace(_queue=["on_release"])
    stuck = SimpleNamespace(_queue=["on_release"])  # a subscriber that does not read: never taken
    pub = SimpleNamespace(impl=SimpleNamespace(connections=[reading, stuck]))
    threading.Timer(0.05, lambda: setattr(reading, "_queue", [])).start()
    t0 = time.monotonic()
    publish.flush(pub, timeout=0.3)
    took = time.monotonic() - t0
    assert reading._queue == [] and 0.25 <= took < 1.0  # waited for the reader, then at most the timeout
    t0 = time.monotonic()
    publish.flush(SimpleNamespace(impl=SimpleNamespace(connections=[reading])), timeout=5.0)
    assert time.monotonic() - t0 < 0.1  # nothing waiting: no wait


def test_a_stop_that_never_reached_anyone_is_not_shown_resolved_once_it_is_released():
    """A reviewer's sequence: the start fails (no one), periodic fails during its backoff, the
    behaviour is released; the next periodic, inactive, sent nothing and must resolve nothing."""
    p = active(subscribers=0)
    runner = ActionRunner(p, lambda level, text: None)
    assert not runner._guard("start", lambda: p.start(None))
    assert not runner._guard("periodic", p.periodic)
    p.active = False  # released
    assert runner._guard("periodic", p.periodic)  # nothing to do: not a failure
    assert runner.stats.failing == "periodic" and not runner.stats.last_error.startswith("resolved")
