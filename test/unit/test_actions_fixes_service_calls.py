"""Acceptance fixes of the `service` plugin (no master: the proxy is a fake): a hung call blocks the
service it hangs in, not the action (a reload that points the action at another service calls it
at once, and the message names the hung service); a response with `success: false` is a failure."""
import threading
import time

import pytest

pytest.importorskip("rospy")
pytest.importorskip("std_srvs.srv")

from std_srvs.srv import SetBoolResponse, TriggerResponse  # noqa: E402

from rubass.actions.base import Context  # noqa: E402
from rubass.actions.status import NOTHING_DONE  # noqa: E402
from rubass.lang.library import ActionDef  # noqa: E402
from rubass.ros.actions import service  # noqa: E402
from rubass.ros.actions.service import ServicePlugin, ServiceRefused  # noqa: E402

CTX = Context(1, 3)


class Proxy:
    """A ServiceProxy for `name`: answers `response`, or hangs until `go` is set."""

    def __init__(self, name, response=None, hang=False):
        self.resolved_name = name
        self.response = response
        self.hang = hang
        self.go = threading.Event()
        self.calls = 0

    def call(self, request):
        self.calls += 1
        if self.hang:
            self.go.wait(30)
        return self.response

    def close(self):
        pass


def brk(service_name, proxy, type_="std_srvs/Trigger", **params):
    p = ServicePlugin(ActionDef("brk", "service", dict({"service": service_name, "type": type_, "timeout": 0.3,
                                                        "call_on": ["start"]}, **params)))
    p.setup()
    p.proxy = proxy
    p._advertised = lambda: True
    return p


def test_a_reload_that_points_the_action_at_a_working_service_calls_it_at_once():
    hang = Proxy("/hang", hang=True)
    first = brk("/hang", hang)
    try:
        with pytest.raises(TimeoutError, match="service /hang did not answer within 0.3 s"):
            first.start(CTX)
        with pytest.raises(TimeoutError, match="the previous call to /hang has not returned"):
            brk("/hang", hang).start(CTX)  # a reload that keeps the service: still one call in it
        works = Proxy("/brake", TriggerResponse(True, "ok"))
        brk("/brake", works).start(CTX)  # the reload pointed it at /brake: called, not blocked by /hang
        assert works.calls == 1 and hang.calls == 1
    finally:
        hang.go.set()
        end = time.monotonic() + 5
        while service._HUNG and time.monotonic() < end:
            time.sleep(0.01)
            for key, (thread, *_rest) in list(service._HUNG.items()):
                if not thread.is_alive():
                    service._HUNG.pop(key, None)


@pytest.mark.parametrize("type_,response,text", [
    ("std_srvs/Trigger", TriggerResponse(False, "refused"), "service /b answered success: false: 'refused'"),
    ("std_srvs/SetBool", SetBoolResponse(False, ""), "service /b answered success: false$"),
])
def test_a_response_with_success_false_is_a_failure(type_, response, text):
    p = brk("/b", Proxy("/b", response), type_)
    with pytest.raises(ServiceRefused, match=text):
        p.start(CTX)


def test_a_response_with_success_true_or_no_success_field_is_a_success_and_a_phase_not_called_did_nothing():
    assert brk("/b", Proxy("/b", TriggerResponse(True, "ok"))).start(CTX) is None
    assert brk("/b", Proxy("/b", TriggerResponse(True, "ok"))).release(CTX) is NOTHING_DONE
    assert brk("/b", Proxy("/b", object()), "std_srvs/Empty").start(CTX) is None


def test_a_service_the_master_does_not_know_fails_at_once_whatever_the_timeout():
    p = brk("/nobrake", Proxy("/nobrake"), timeout=5.0)
    p._advertised = lambda: False
    t0 = time.monotonic()
    with pytest.raises(IOError, match=r"service /nobrake does not exist \(not advertised on the master\)"):
        p.start(CTX)
    assert time.monotonic() - t0 < 2.0, "not after its 5 s timeout"
    assert p.proxy.calls == 0
