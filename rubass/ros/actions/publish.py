"""The `publish` plugin: a message once at start and then at its rate while active."""
from __future__ import annotations

import time
import warnings
from typing import Any, Dict, Optional

import genpy
import roslib.message
import rospy

from ..reach import Reach
from .arbiter import take_seat
from ...actions.base import ActionPlugin, ActionSetupError, Context, Skipped
from ...actions.status import NOTHING_DONE


def ros_class(lookup: Any, type_name: str, where: str, kind: str) -> Any:
    """A message or service class by its 'package/Type' name; ActionSetupError if unknown."""
    try:
        cls = lookup(type_name)
    except Exception:  # roslib raises ValueError, ImportError, … for a bad or missing package
        cls = None
    if cls is None:
        raise ActionSetupError(f"{where}: unknown {kind} type '{type_name}' (is its package installed?)")
    return cls


def build_message(cls: Any, fields: Dict[str, Any], where: str) -> Any:
    """A message of class cls with the YAML field values; ActionSetupError naming the field."""
    msg = cls()  # every field zero, empty or false
    try:
        if fields:
            genpy.message.fill_message_args(msg, [fields])
        msg.serialize(_Sink())  # catches values of the wrong type now, not at the first stop
    except Exception as exc:  # genpy raises MessageException, ValueError, TypeError, struct.error, …
        raise ActionSetupError(f"{where}: {exc}") from None
    return msg


def stamps_itself(cls: Any, fields: Any) -> bool:
    """Whether each publication of this message gets the current ROS time in `header.stamp`: its type
    has a top-level std_msgs/Header `header` and the library's fields do not set its stamp."""
    slots, types = list(getattr(cls, "__slots__", ())), list(getattr(cls, "_slot_types", ()))
    if "header" not in slots or len(types) != len(slots) or types[slots.index("header")] not in (
            "std_msgs/Header", "Header"):
        return False
    if fields is None:
        return True
    if not isinstance(fields, dict):  # positional values: the library gave the header itself
        return False
    header = fields.get("header")
    return header is None or (isinstance(header, dict) and "stamp" not in header)


class _Sink:
    def write(self, data: bytes) -> None:
        pass


SEND_TIMEOUT = 0.1  # s a write to one subscriber may block before that subscriber's connection is dropped
LOST_AFTER = 10.0  # s an active stop may reach no one after its subscribers went before it is a failure
_clock = time.monotonic  # LOST_AFTER's clock (a test moves it by hand)


def action_publisher(topic: str, cls: Any) -> rospy.Publisher:
    """An action's publisher: written synchronously (no thread hand-off on the stop's way), each
    subscriber's socket with a send timeout of SEND_TIMEOUT.

    rospy writes each subscriber in turn: one that stops reading (a node stopped, a link cut: TCP
    keeps its connection up to 15 min) fills its socket's buffers, and its write then blocked every
    publication, to the base too (a tester's run: the base lost the stop 35 s after a recorder's link
    was cut, while ~heartbeat went on). A write that cannot go on for SEND_TIMEOUT now fails, and
    rospy drops that connection (reconnect.py tells its node, once it answers, to connect again).
    A queued publisher (a rospy thread per subscriber) isolates as well, but its hand-off doubled
    the `limit` action's added latency (bench/README.md)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # rospy warns that queue_size is not set: on purpose
        pub = rospy.Publisher(topic, cls, queue_size=None, tcp_nodelay=True)
    _bound_writes(pub.impl)
    return pub


def _bound_writes(impl: Any) -> None:
    """Give each subscriber connection of this topic (rospy's _PublisherImpl, shared by the process's
    publishers of it) a send timeout as it is added."""
    if impl is None or getattr(impl, "_rubass_bounded", False):
        return
    add = impl.add_connection

    def add_connection(conn: Any) -> Any:
        sock = getattr(conn, "socket", None)
        if sock is not None:
            sock.settimeout(SEND_TIMEOUT)  # sendall raises after it: rospy's publish drops the connection
        return add(conn)
    impl.add_connection = add_connection
    impl._rubass_bounded = True


class PublishPlugin(ActionPlugin):
    def __init__(self, action: Any) -> None:
        super().__init__(action)
        self.period = 1.0 / float(self.params["rate"])
        self.pub: Optional[rospy.Publisher] = None
        self.seat: Any = None
        self.reach = Reach()
        self.reached = False  # this activation's start reached a subscriber
        self.gone_at: Optional[float] = None  # ... and every subscriber has gone since then (monotonic)
        self.lost = False  # ... for LOST_AFTER: reported once, by periodic

    def setup(self) -> None:
        cls = ros_class(roslib.message.get_message_class, self.params["type"], f"action '{self.name}'", "message")
        self.msg = build_message(cls, self.params.get("message") or {}, f"action '{self.name}': message")
        release = self.params.get("on_release")
        self.release_msg = None if release is None else build_message(cls, release, f"action '{self.name}': on_release")
        self.stamp = stamps_itself(cls, self.params.get("message") or {})
        self.release_stamp = release is not None and stamps_itself(cls, release)
        # Created at start-up, so that subscribers are connected before the first violation.
        self.pub = action_publisher(self.params["topic"], cls)
        # among the actions on this topic only the highest-priority active one publishes (§16)
        self.seat = take_seat(self.params["topic"], self.name, self.action.priority, lambda: self.wake())

    def _publish(self, msg: Any, stamp: bool = False) -> bool:
        """Publish if this action owns its topic (stamped now if `stamp`); whether it did."""
        with self.seat.turn() as mine:
            if mine and self.pub is not None:
                if stamp:  # a stop stamped 0 is dropped as stale by a node that checks its age
                    msg.header.stamp = rospy.get_rostime()
                self.pub.publish(msg)
            return mine and self.pub is not None

    def start(self, ctx: Context) -> None:
        assert self.pub is not None
        self.seat.activate()
        if not self._publish(self.msg, self.stamp):
            # a higher-priority action owns the topic: nothing sent, nothing proved; retried (it is
            # this action's turn once that one releases; meanwhile a failed start stays shown)
            raise Skipped(f"{self.params['topic']} is held by a higher-priority action")
        self.reached, self.gone_at, self.lost = False, None, False
        if self.pub.get_num_connections() == 0:
            # not an error rospy would report: the message just went nowhere. A failure, so it is
            # logged, counted in /diagnostics and retried (0.05 s, 0.1 s, … then every 1 s); the
            # periodic publication also reaches a subscriber that connects later.
            raise IOError(f"{self.reach.why(self.params['topic'], self.params['type'])}: the message reached "
                          f"no one; it is sent again as soon as one does")
        self.reached = True

    def periodic(self) -> Any:
        if not (self.active and self.pub is not None and self._publish(self.msg, self.stamp)):
            return NOTHING_DONE  # nothing sent: proves nothing (an inactive periodic must not show a failure resolved)
        if self.pub.get_num_connections() > 0:
            self.gone_at, self.lost = None, False
            return None
        if not self.reached or self.lost:
            return NOTHING_DONE  # the start's own failure says it (retried), or this loss was reported
        now = _clock()
        if self.gone_at is None:
            self.gone_at = now
        if now - self.gone_at < LOST_AFTER:
            return NOTHING_DONE  # a subscriber restarting, a probe that came and went: not yet
        # every subscriber the start reached has gone for LOST_AFTER (the base killed, its link cut):
        # an active stop that reaches no one is a failure, reported once and shown until a
        # publication reaches one again or the stop is released
        self.lost = True
        raise IOError(f"{self.reach.why(self.params['topic'], self.params['type'])}: the message reached no one "
                      f"for {now - self.gone_at:.0f} s since its subscribers went; it is sent again at "
                      f"{float(self.params['rate']):g} Hz")

    def release(self, ctx: Context) -> Any:
        try:
            if self.release_msg is not None and self.pub is not None and self._publish(self.release_msg,
                                                                                        self.release_stamp) \
                    and self.pub.get_num_connections() > 0:
                return None
            if self.lost:  # an active stop that reached no one since its subscribers went: no longer active
                return None
            # nothing that reached anyone (no on_release, a higher-priority action owns the topic, no
            # subscriber): a failed start is not shown fixed by it
            return NOTHING_DONE
        finally:
            self.reached, self.gone_at, self.lost = False, None, False
            self.seat.deactivate()  # after on_release: the next action on the topic is woken to publish

    def close(self) -> None:
        if self.seat is not None:
            self.seat.leave()
        if self.pub is not None:
            self.pub.unregister()
            self.pub = None
