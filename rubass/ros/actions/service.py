"""The `service` plugin: calls a ROS service with fixed request fields, with a timeout."""
from __future__ import annotations

import threading
from typing import Any, List

import rosgraph
import roslib.message
import rospy

from ...actions.base import ActionPlugin, Context
from ..rpc import proxy
from .publish import build_message, ros_class


class ServicePlugin(ActionPlugin):
    def setup(self) -> None:
        cls = ros_class(roslib.message.get_service_class, self.params["type"], f"action '{self.name}'", "service")
        self.request = build_message(cls._request_class, self.params.get("request") or {},
                                     f"action '{self.name}': request")
        self.proxy = rospy.ServiceProxy(self.params["service"], cls)

    def _call(self) -> None:
        """Call with a timeout; a call that hangs is abandoned (its thread is a daemon)."""
        timeout = float(self.params["timeout"])
        result: List[Any] = []

        def call() -> None:
            try:  # a service that appears within the timeout (its node restarting) is called at once
                self.proxy.wait_for_service(timeout)
                result.append(self.proxy.call(self.request))
            except Exception as exc:  # rospy.ServiceException, ROSException, ROSInterruptException
                result.append(exc)

        worker = threading.Thread(target=call, name=f"rubass-service-{self.name}", daemon=True)
        worker.start()
        worker.join(timeout)
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
            self._call()

    def hold(self, ctx: Context) -> None:
        if "hold" in self.params["call_on"]:
            self._call()

    def release(self, ctx: Context) -> None:
        if "release" in self.params["call_on"]:
            self._call()

    def close(self) -> None:
        self.proxy.close()
