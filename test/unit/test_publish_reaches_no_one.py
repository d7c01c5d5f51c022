"""An active `publish` whose subscribers have all gone for 10 s (the base killed, its link cut) is
a failure, once, so /diagnostics shows the stop reaching no one (an acceptance tester's finding:
it stayed OK while the stop went to nobody at its rate), until a publication reaches a subscriber
again; and its publisher's write to one subscriber blocks SEND_TIMEOUT at most, so one that stops
reading cannot hold the stop from the others."""
import pytest

pytest.importorskip("rospy")

from test_publish_release_unowned import plugin  # noqa: E402

from rubass.actions.runner import ActionRunner  # noqa: E402
from rubass.actions.status import NOTHING_DONE  # noqa: E402
from rubass.ros.actions import publish  # noqa: E402


def active(subscribers):
    p = plugin(mine=True, subscribers=subscribers)
    p.params["rate"], p.name, p.active, p.period = 20.0, "stop", True, 0.05
    p.reached, p.gone_at, p.lost = False, None, False
    return p


@pytest.fixture(autouse=True)
def clock(monkeypatch):
    """The monotonic clock publish.py reads, moved by hand."""
    now = [1000.0]
    monkeypatch.setattr(publish, "_clock", lambda: now[0])
    return now


def test_a_periodic_publication_that_reaches_no_one_after_the_start_did_is_a_failure_once(clock):
    p = active(subscribers=1)
    p.start(None)  # reached the base
    p.pub.subscribers = 0  # the base has gone
    assert p.periodic() is NOTHING_DONE  # at once: a subscriber restarting, a probe that came and went
    clock[0] += publish.LOST_AFTER - 0.1
    assert p.periodic() is NOTHING_DONE
    clock[0] += 0.1
    with pytest.raises(IOError, match=r"no node subscribes to /cmd: the message reached no one for 10 s since its "
                                      r"subscribers went; it is sent again at 20 Hz"):
        p.periodic()
    assert p.periodic() is NOTHING_DONE  # reported once, not at every period (the count stays a count)
    assert len(p.pub.sent) == 5  # still sent: a subscriber that connects meanwhile gets it
    p.pub.subscribers = 1
    assert p.periodic() is None  # reaches one: that resolves it


def lose(p, runner, clock):
    """Every subscriber goes, for LOST_AFTER: the periodic that then fails, through the runner."""
    p.pub.subscribers = 0
    assert runner._guard("periodic", p.periodic)
    clock[0] += publish.LOST_AFTER
    return runner._guard("periodic", p.periodic)


def test_the_failure_is_counted_shown_and_resolved_by_the_next_publication_that_reaches_one(clock):
    p = active(subscribers=1)
    logs = []
    runner = ActionRunner(p, lambda level, text: logs.append((level, text)))
    assert runner._guard("start", lambda: p.start(None))
    assert not lose(p, runner, clock)
    assert runner.stats.failing == "periodic" and runner.stats.failures == 1
    assert "periodic: OSError: no node subscribes to /cmd: the message reached no one" in runner.stats.last_error
    clock[0] += 5.0
    assert runner._guard("periodic", p.periodic) and runner.stats.failures == 1  # not counted again
    assert runner.stats.failing == "periodic"  # still shown
    p.pub.subscribers = 1
    assert runner._guard("periodic", p.periodic)
    assert runner.stats.failing == ""
    assert not lose(p, runner, clock)
    p.pub.subscribers = 1  # the next activation's start reaches one: that resolves it too
    assert runner._guard("start", lambda: p.start(None))
    assert runner.stats.failing == ""


def test_a_start_that_reached_no_one_is_the_only_failure_its_periodic_adds_none():
    """The start's own failure is retried with backoff and counted so (I/test_reliability_overload.py):
    its periodic publications must neither count one at each period nor take its place."""
    p = active(subscribers=0)
    runner = ActionRunner(p, lambda level, text: None)
    assert not runner._guard("start", lambda: p.start(None))
    for _ in range(5):
        assert runner._guard("periodic", p.periodic)  # nothing proved, nothing failed
    assert runner.stats.failing == "start" and runner.stats.failures == 1


def test_each_subscriber_connection_of_an_action_publisher_gets_a_send_timeout(monkeypatch):
    """So a subscriber that stops reading holds a publication SEND_TIMEOUT at most: rospy's publish
    then drops that connection (I/test_publish_stuck_subscriber.py); written synchronously otherwise."""
    from types import SimpleNamespace

    added = []
    impl = SimpleNamespace(add_connection=added.append)
    made = []

    def publisher(*a, **kw):
        made.append(kw)
        return SimpleNamespace(impl=impl)
    monkeypatch.setattr(publish.rospy, "Publisher", publisher)
    publish.action_publisher("/stop", object)
    publish.action_publisher("/stop", object)  # a second action on the topic: one impl, wrapped once
    assert made[0]["queue_size"] is None  # synchronous: no thread hand-off on the stop's way
    timeouts = []
    conn = SimpleNamespace(socket=SimpleNamespace(settimeout=timeouts.append))
    impl.add_connection(conn)
    assert timeouts == [publish.SEND_TIMEOUT] and added == [conn]


def test_a_stop_that_never_reached_anyone_is_not_shown_resolved_once_it_is_released():
    """A reviewer's sequence: the start fails (no one), periodic runs during its backoff, the
    behaviour is released; the next periodic, inactive, sent nothing and must resolve nothing."""
    p = active(subscribers=0)
    runner = ActionRunner(p, lambda level, text: None)
    assert not runner._guard("start", lambda: p.start(None))
    assert runner._guard("periodic", p.periodic)
    p.active = False  # released
    assert runner._guard("periodic", p.periodic)  # nothing to do: not a failure, not a success
    assert runner.stats.failing == "start" and not runner.stats.last_error.startswith("resolved")


def test_releasing_a_stop_that_reached_no_one_since_its_subscribers_went_ends_that_failure(clock):
    p = active(subscribers=1)
    runner = ActionRunner(p, lambda level, text: None)
    assert runner._guard("start", lambda: p.start(None))
    assert not lose(p, runner, clock)
    p.active = False
    assert runner._guard("release", lambda: p.release(None))
    assert runner.stats.failing == ""  # no active stop reaches no one any more
