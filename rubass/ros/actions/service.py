"""The `service` plugin: calls a ROS service with fixed request fields, with a timeout; at most one
abandoned (hung) call per action is ever in flight."""
from __future__ import annotations

import threading
import time
from typing import Any, Dict, List, Tuple

import rosgraph
import roslib.message
import rospy

from ...actions.base import ActionPlugin, Context, Skipped
from ..rpc import proxy
from .publish import build_message, ros_class


# the abandoned call of each action (by name) while it has not returned: (thread, monotonic start,
# its stage). Kept here, not on the plugin, so that a reload that rebuilds the action (a new timeout)
# does not start a second abandoned call beside the first: at most one per action, across reloads
_HUNG: Dict[str, Tuple[threading.Thread, float, List[str]]] = {}


class ServicePlugin(ActionPlugin):
    def setup(self) -> None:
        cls = ros_class(roslib.message.get_service_class, self.params["type"], f"action '{self.name}'", "service")
        self.request = build_message(cls._request_class, self.params.get("request") or {},
                                     f"action '{self.name}': request")
        self.proxy = rospy.ServiceProxy(self.params["service"], cls)
        self.call_timeout = float(self.params["timeout"]) + 1.0  # the runner's stuck bound: the call and _advertised

    def _previous_returned(self, phase: str) -> None:
        """Raise while the call abandoned last time is still in the service (a wait for the service
        that overran the timeout ends on its own within rospy's 0.3 s poll: waited for): a start or
        release fails at once, a hold (every tick) is skipped, not counted as another failure."""
        hung = _HUNG.get(self.name)
        if hung is None:
            return
        thread, since, stage = hung
        if stage[0] == "waiting":
            thread.join(0.4)
        if thread.is_alive():
            text = (f"the previous call to {self.params['service']} has not returned after "
                    f"{time.monotonic() - since:.1f} s: not calling it again until it does")
            raise Skipped(text) if phase == "hold" else TimeoutError(text)
        _HUNG.pop(self.name, None)

    def _call(self, phase: str) -> None:
        """Call with a timeout; a call that hangs is abandoned (its thread is a daemon), and while it has
        not returned no other is started: a new attempt fails at once (one thread per attempt leaked)."""
        timeout = float(self.params["timeout"])
        self._previous_returned(phase)
        result: List[Any] = []
        stage = ["waiting"]  # then "calling": a wait for the service ends on its own (rospy polls it every 0.3 s)

        def call() -> None:
            try:  # a service that appears within the timeout (its node restarting) is called at once
                self.proxy.wait_for_service(timeout)
                stage[0] = "calling"
                result.append(self.proxy.call(self.request))
            except Exception as exc:  # rospy.ServiceException, ROSException, ROSInterruptException
                result.append(exc)

        worker = threading.Thread(target=call, name=f"rubass-service-{self.name}", daemon=True)
        worker.start()
        started = time.monotonic()
        worker.join(timeout)
        if worker.is_alive():
            _HUNG[self.name] = (worker, started, stage)
        if not result or type(result[0]) is rospy.ROSException:  # timed out: waiting for it, or in the call
            if not self._advertised():  # asked only now, to say why
                raise IOError(f"service {self.params['service']} does not exist (not advertised on the master)")
            raise TimeoutError(f"service {self.params['service']} did not answer within {timeout:g} s")
        if isinstance(result[0], Exception):
            raise IOError(f"service {self.params['service']}: {result[0]}")

    def _advertised(self) -> bool:
        """Whether the master knows the service; True when the master cannot say within 0.5 s."""
        try:
            code, _, _ = proxy(rosgraph.get_master_uri(), 0.5).lookupService(rospy.get_name(),
                                                                             self.proxy.resolved_name)
        except Exception:  # master unreachable or hung: the timeout is the answer
            return True
        return code == 1

    def start(self, ctx: Context) -> None:
        if "start" in self.params["call_on"]:
            self._call("start")

    def hold(self, ctx: Context) -> None:
        if "hold" in self.params["call_on"]:
            self._call("hold")

    def release(self, ctx: Context) -> None:
        if "release" in self.params["call_on"]:
            self._call("release")

    def close(self) -> None:
        self.proxy.close()
