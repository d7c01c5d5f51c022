"""A `publish` release that sent nothing because a higher-priority action owns the topic does not
count as an attempt that worked (review finding: it marked a failed start resolved)."""
import contextlib

import pytest

pytest.importorskip("rospy")

from rubass.actions.status import NOTHING_DONE  # noqa: E402
from rubass.ros.actions.publish import PublishPlugin  # noqa: E402


class Seat:
    def __init__(self, mine):
        self.mine, self.active = mine, True

    @contextlib.contextmanager
    def turn(self):
        yield self.mine

    def deactivate(self):
        self.active = False


class Pub:
    def __init__(self):
        self.sent = []

    def publish(self, msg):
        self.sent.append(msg)


def plugin(mine):
    p = PublishPlugin.__new__(PublishPlugin)  # the release path only: no master, no rospy publisher
    p.release_msg, p.release_stamp, p.pub, p.seat = object(), False, Pub(), Seat(mine)
    return p


def test_a_release_another_action_kept_from_the_topic_did_nothing():
    p = plugin(mine=False)
    assert p.release(None) is NOTHING_DONE
    assert p.pub.sent == [] and not p.seat.active


def test_a_release_that_published_its_on_release_message_worked():
    p = plugin(mine=True)
    assert p.release(None) is None
    assert p.pub.sent == [p.release_msg] and not p.seat.active
