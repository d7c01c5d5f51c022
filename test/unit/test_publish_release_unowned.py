"""A `publish` phase that reached no one does not count as an attempt that worked: a release kept off
the topic by a higher-priority action (review finding) or sent to no subscriber, and a start retried
while a higher-priority action owns the topic (re-sweep findings: each marked a failed start
"resolved" and /diagnostics went OK)."""
import contextlib

import pytest

pytest.importorskip("rospy")

from rubass.actions.base import Skipped  # noqa: E402
from rubass.actions.status import NOTHING_DONE  # noqa: E402
from rubass.ros.actions.publish import PublishPlugin  # noqa: E402


class Seat:
    def __init__(self, mine):
        self.mine, self.active = mine, True

    def activate(self):
        self.active = True

    @contextlib.contextmanager
    def turn(self):
        yield self.mine

    def deactivate(self):
        self.active = False


class Pub:
    def __init__(self, subscribers=1):
        self.sent, self.subscribers = [], subscribers

    def publish(self, msg):
        self.sent.append(msg)

    def get_num_connections(self):
        return self.subscribers


class NoSubscriber:
    def why(self, topic, published):
        return f"no node subscribes to {topic}"


def plugin(mine, subscribers=1):
    p = PublishPlugin.__new__(PublishPlugin)  # start and release only: no master, no rospy publisher
    p.msg, p.stamp, p.params = object(), False, {"topic": "/cmd"}
    p.release_msg, p.release_stamp, p.pub, p.seat = object(), False, Pub(subscribers), Seat(mine)
    p.params["type"] = "std_msgs/Bool"
    p.reached = p.lost = False  # set up by __init__, which is skipped here
    p.reach = NoSubscriber()  # the master is not asked here: test/integration/test_publish_wrong_type.py
    return p


def test_a_release_another_action_kept_from_the_topic_did_nothing():
    p = plugin(mine=False)
    assert p.release(None) is NOTHING_DONE
    assert p.pub.sent == [] and not p.seat.active


def test_a_release_that_published_its_on_release_message_worked():
    p = plugin(mine=True)
    assert p.release(None) is None
    assert p.pub.sent == [p.release_msg] and not p.seat.active


def test_a_release_that_reached_no_subscriber_did_nothing():
    p = plugin(mine=True, subscribers=0)
    assert p.release(None) is NOTHING_DONE


def test_a_start_while_a_higher_priority_action_owns_the_topic_is_skipped_not_a_success():
    p = plugin(mine=False)
    with pytest.raises(Skipped):
        p.start(None)
    assert p.pub.sent == [] and p.seat.active  # still its turn to come


def test_a_start_that_reached_a_subscriber_works_and_one_that_reached_none_fails():
    p = plugin(mine=True)
    assert p.start(None) is None and p.pub.sent == [p.msg]
    with pytest.raises(IOError):
        plugin(mine=True, subscribers=0).start(None)

