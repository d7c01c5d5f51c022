"""The `service` plugin: calls a ROS service with fixed request fields, with a timeout; at most one
abandoned (hung) call per service is ever in flight. A service the master does not know fails at
once; a response whose boolean `success` is false is a failed attempt (retried as any failure)."""
from __future__ import annotations

import threading
import time
from typing import Any, Dict, List, Optional, Tuple

import rosgraph
import roslib.message
import rospy

from ...actions.base import ActionPlugin, Context, Skipped
from ...actions.status import NOTHING_DONE, topic_shown
from ..rpc import proxy
from .publish import build_message, ros_class

LOOKUP_TIMEOUT = 0.5  # how long the master may take to say whether it knows the service

# the abandoned call of each service (resolved name, type) while it has not returned: (thread,
# monotonic start, its stage, the service's name as the library gave it). Kept here, not on the
# plugin, so that a reload that rebuilds the action (a new timeout) does not start a second abandoned
# call beside the first; keyed by the service, not the action, so that a reload that points the
# action at another service calls that one at once
_HUNG: Dict[Tuple[str, str], Tuple[threading.Thread, float, List[str], str]] = {}


class ServiceRefused(Exception):
    """The service answered, with `success: false`."""


class ServicePlugin(ActionPlugin):
    def setup(self) -> None:
        cls = ros_class(roslib.message.get_service_class, self.params["type"], f"action '{self.name}'", "service")
        self.request = build_message(cls._request_class, self.params.get("request") or {},
                                     f"action '{self.name}': request")
        self.proxy = rospy.ServiceProxy(self.params["service"], cls)
        self.call_timeout = float(self.params["timeout"]) + 1.0  # the runner's stuck bound: the call and _advertised

    def _key(self) -> Tuple[str, str]:
        return (str(self.proxy.resolved_name), str(self.params["type"]))

    def _previous_returned(self, phase: str) -> None:
        """Raise while the call abandoned last time is still in the service (a lookup on the master
        that overran the timeout ends on its own within LOOKUP_TIMEOUT: waited for): a start or release
        fails at once, a hold (every tick) is skipped, not counted as another failure."""
        hung = _HUNG.get(self._key())
        if hung is None:
            return
        thread, since, stage, service = hung
        if stage[0] == "waiting":
            thread.join(LOOKUP_TIMEOUT + 0.1)
        if thread.is_alive():
            text = (f"the previous call to {service} has not returned after "
                    f"{time.monotonic() - since:.1f} s: not calling it again until it does")
            raise Skipped(text) if phase == "hold" else TimeoutError(text)
        if _HUNG.get(self._key()) is hung:
            _HUNG.pop(self._key(), None)

    def _call(self, phase: str) -> None:
        """Call with a timeout; a call that hangs is abandoned (its thread is a daemon), and while it has
        not returned no other is started: a new attempt fails at once (one thread per attempt leaked)."""
        timeout = float(self.params["timeout"])
        self._previous_returned(phase)
        service = topic_shown(self.params["service"], self.proxy.resolved_name, "the action library")  # ns, remap
        result: List[Any] = []
        stage = ["waiting"]  # then "calling": the lookup on the master ends on its own (LOOKUP_TIMEOUT)

        def call() -> None:
            try:  # one lookup (bounded), then the call: a service the master does not know fails at once
                if not self._advertised():
                    result.append(_MISSING)
                    return
                stage[0] = "calling"
                result.append(self.proxy.call(self.request))
            except Exception as exc:  # rospy.ServiceException, ROSException, ROSInterruptException
                result.append(exc)

        worker = threading.Thread(target=call, name=f"rubass-service-{self.name}", daemon=True)
        worker.start()
        started = time.monotonic()
        worker.join(timeout)
        if worker.is_alive():
            _HUNG[self._key()] = (worker, started, stage, service)
        if result and result[0] is _MISSING:
            raise IOError(f"service {service} does not exist (not advertised on the master)")
        if not result or type(result[0]) is rospy.ROSException:  # timed out in the call
            raise TimeoutError(f"service {service} did not answer within {timeout:g} s")
        if isinstance(result[0], Exception):
            raise IOError(f"service {service}: {result[0]}")
        refused = _refusal(result[0])
        if refused is not None:
            raise ServiceRefused(f"service {service} answered success: false{refused}")

    def _advertised(self) -> bool:
        """Whether the master knows the service; True when the master cannot say within LOOKUP_TIMEOUT
        (then the call itself says what is wrong, or the timeout does)."""
        try:
            code, _, _ = proxy(rosgraph.get_master_uri(), LOOKUP_TIMEOUT).lookupService(rospy.get_name(),
                                                                                        self.proxy.resolved_name)
        except Exception:  # master unreachable or hung: the timeout is the answer
            return True
        return code == 1

    def _phase(self, phase: str) -> Any:
        """Call in this phase if `call_on` names it; NOTHING_DONE when it does not (a release that calls
        nothing resolves no failed start: only a call that succeeded does)."""
        if phase not in self.params["call_on"]:
            return NOTHING_DONE
        self._call(phase)
        return None

    def start(self, ctx: Context) -> Any:
        return self._phase("start")

    def hold(self, ctx: Context) -> Any:
        return self._phase("hold")

    def release(self, ctx: Context) -> Any:
        return self._phase("release")

    def close(self) -> None:
        self.proxy.close()


_MISSING = object()  # the master said it does not know the service


def _refusal(response: Any) -> Optional[str]:
    """None unless the response has a boolean `success` field that is false; then its `message` (if a
    string field) as text to add to the error."""
    slots = list(getattr(response, "__slots__", ()))
    types = list(getattr(response, "_slot_types", ()))
    if "success" not in slots or len(types) != len(slots) or types[slots.index("success")] != "bool":
        return None
    if response.success:
        return None
    message = getattr(response, "message", None) if "message" in slots else None
    return f": {message!r}" if isinstance(message, str) and message else ""
