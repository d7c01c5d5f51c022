"""The `limit` plugin (LANGUAGE.md §16): while active, every velocity command on `input` is
republished on `topic` with the named axes clamped, and the latest one again at `rate` when the
input is slower; no command for `timeout` means zero, at `rate`; while inactive, nothing.

The input is read from set-up on (rospy.AnyMsg, tcp_nodelay), so the first command after a
start is not lost to connection set-up and a start can republish the latest command at once.
Each command is clamped and published on the subscriber's own thread (no hand-off), the zero
commands on the runner's thread; one lock orders them, and the arbiter decides whether this
action owns its topic at all.
"""
from __future__ import annotations

import threading
import time
from typing import Any, Dict, Optional, Tuple

import roslib.message
import rospy

from ...actions.clamp import AXES, clamp_twist
from ..reach import Reach
from .arbiter import take_seat
from ...actions.base import ActionPlugin, Context, Skipped
from ...actions.status import NOTHING_DONE, RESOLVED, topic_shown
from .publish import action_publisher, ros_class

LOG_EVERY = 5.0
# the latest well-typed command on each input, by (resolved name, message type): what came is a
# fact about the topic, so a limit that a reload has just rebuilt starts from it, not from zero. Keyed
# by type too: a Twist limit must never read the TwistStamped a limit of another type took from the
# same input (its bytes read as a Twist are garbage, clamped to the maximum)
_LATEST: Dict[Tuple[str, str], Tuple[bytes, float]] = {}


class LimitPlugin(ActionPlugin):
    def __init__(self, action: Any) -> None:
        super().__init__(action)
        self.period = 1.0 / float(self.params["rate"])
        self.timeout = float(self.params["timeout"])
        self.type = self.params["type"]
        self.ranges: Dict[str, Any] = {axis: self.params.get(axis) for axis in AXES if self.params.get(axis)}
        self._lock = threading.Lock()
        self._on = False  # between start and release (the runner's `active` flips earlier, on submit)
        self._raw: Optional[bytes] = None  # the latest command, as it came
        self._raw_at = float("-inf")  # its arrival (time.monotonic())
        self._due = False  # publish at the next periodic although a command is fresh (handed the topic)
        self._pub_at = float("-inf")  # this action's latest publication (time.monotonic())
        self._last_log = float("-inf")
        self.reach = Reach()
        self.input_errors = 0
        self.pub: Optional[rospy.Publisher] = None
        self.sub: Optional[rospy.Subscriber] = None
        self.seat: Any = None

    def setup(self) -> None:
        self.cls = ros_class(roslib.message.get_message_class, self.type, f"action '{self.name}'", "message")
        self.stamped = self.type.endswith("Stamped")
        self.pub = action_publisher(self.params["topic"], self.cls)
        self.seat = take_seat(self.params["topic"], self.name, self.action.priority, self._handed_over)
        self.input = rospy.resolve_name(self.params["input"])
        self.sub = rospy.Subscriber(self.params["input"], rospy.AnyMsg, self._on_input, tcp_nodelay=True)

    def _input_shown(self) -> str:
        """The input topic as the robot names it (namespace, remapping), the library's spelling beside."""
        return topic_shown(self.params["input"], self.input, "the action library")

    # -- the subscriber's thread -----------------------------------------------------------
    def _on_input(self, raw: Any) -> None:
        now = time.monotonic()
        got = raw._connection_header.get("type", "")
        if got != self.type:
            self._fail(f"{self._input_shown()} carries {got}, not {self.type} as action '{self.name}' says: "
                       f"its commands are ignored (so after {self.timeout:g} s it publishes zero)")
            return
        _LATEST[(self.input, self.type)] = (raw._buff, now)
        self._input_ok()
        with self._lock:
            if not (self._on and self.active):  # decoded only if a start needs it; `active` goes false as its
                self._raw, self._raw_at = raw._buff, now  # release is dispatched (a stop released with it
                return  # must not hand it the topic for one command before its release runs)
            msg = self._clamped(raw._buff)
            if msg is None:
                return
            self._raw, self._raw_at = raw._buff, now
            self._due = False
            self._publish(msg)

    # -- the runner's thread ---------------------------------------------------------------
    def start(self, ctx: Context) -> None:
        with self._lock:
            self._on = True
            self.seat.activate()
            reached = self._publish(self._current())
            self._due = False
        if reached < 0:  # a higher-priority action owns the topic: nothing proved; retried, not counted
            raise Skipped(f"{self.params['topic']} is held by a higher-priority action")
        if reached == 0:
            raise IOError(f"{self.reach.why(self.params['topic'], self.type)}: the limited command reached no "
                          f"one; commands go on being published as they come")

    def periodic(self) -> None:
        with self._lock:
            if not (self._on and self.active):  # released (dispatched), its release not yet run: nothing more
                return
            now = time.monotonic()
            if self._due or now - self._raw_at > self.timeout or now - self._pub_at >= 0.9 * self.period:
                # no command for `timeout` is no command to keep moving: zero, at `rate`. Just
                # handed the topic: the latest command if still fresh (else zero), heard at once.
                # A planner slower than `rate`: its latest command again, so that the output keeps
                # a mux's input alive (twist_mux drops an input silent for its timeout)
                self._publish(self._current())
                self._due = False

    def release(self, ctx: Context) -> Any:
        with self._lock:
            self._on = False
            self.seat.deactivate()
        return NOTHING_DONE  # it stops publishing: no I/O that proves a failed start fixed

    def close(self) -> None:
        with self._lock:  # a command being published finishes first; none is published after
            self._on = False
            endpoints, self.sub, self.pub = (self.sub, self.pub), None, None
        if self.seat is not None:
            self.seat.leave()
        for endpoint in endpoints:
            if endpoint is not None:
                endpoint.unregister()

    # -- helpers (under self._lock) ----------------------------------------------------------
    def _handed_over(self) -> None:
        """The arbiter gave this action the topic: publish at once rather than at the next period."""
        self._due = True
        self.wake()

    def _current(self) -> Any:
        """The latest command clamped, if it came within `timeout`; else a zero command."""
        shared = _LATEST.get((self.input, self.type))
        if shared is not None and shared[1] > self._raw_at:
            self._raw, self._raw_at = shared
        if self._raw is not None and time.monotonic() - self._raw_at <= self.timeout:
            msg = self._clamped(self._raw)
            if msg is not None:
                return msg
        return self._zero()

    def _clamped(self, buff: bytes) -> Any:
        try:
            msg = self.cls().deserialize(buff)
        except Exception as exc:  # genpy.DeserializationError, struct.error: a broken publisher
            self._raw = None
            self._fail(f"a command on {self._input_shown()} cannot be read ({exc.__class__.__name__}: {exc}): "
                       f"ignored")
            return None
        clamp_twist(msg.twist if self.stamped else msg, self.ranges)
        return msg

    def _zero(self) -> Any:
        msg = self.cls()
        if self.stamped:
            msg.header.stamp = rospy.get_rostime()
        return msg

    def _publish(self, msg: Any) -> int:
        """Publish if this action owns the topic; the number of subscribers (-1: not the owner)."""
        with self.seat.turn() as mine:
            if not mine or self.pub is None:
                return -1
            self.pub.publish(msg)
            self._pub_at = time.monotonic()
            return self.pub.get_num_connections()

    def _input_ok(self) -> None:
        """A well-typed command came: a bad-input error no longer makes /diagnostics ERROR."""
        if self.stats.failing == "input":
            self.stats.failing = ""
            self.stats.last_error = RESOLVED + self.stats.last_error

    def _fail(self, text: str) -> None:
        """A bad input is no command (the timeout turns it into zero): counted in /diagnostics,
        logged at most every 5 s."""
        self.input_errors += 1
        self.stats.failures += 1
        self.stats.failing = "input"
        self.stats.last_error = f"input: {text}"
        now = time.monotonic()
        if now - self._last_log >= LOG_EVERY:
            self._last_log = now
            rospy.logerr("rubass: action '%s': %s (%d so far)", self.name, text, self.input_errors)
