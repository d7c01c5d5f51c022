"""~events pairs every start with a release: an active behaviour that a reload removes (not
latched) is released then, and ~events says so (as for a clock jump: test_clockjump_events.py)."""
import os

import pytest

pytest.importorskip("rospy")

from rubass.actions.dispatch import Dispatcher  # noqa: E402
from rubass.engine import Engine  # noqa: E402
from rubass.lang import check_text  # noqa: E402
from rubass.ros import reloading  # noqa: E402

from conftest import ROOT  # noqa: E402

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")
TEXT = "action primitive warn;\nentity a {{ rules: r: topic /x.data > {}; }}\nif (a.r) then {{ warn; }}\n"


class FakeMonitor(reloading.Reloading):
    def __init__(self, engine, reports):
        self.loop = type("Loop", (), {"engine": engine})()
        self.dispatcher = Dispatcher({}, reports.append, lambda: 2.0)
        self.keeper = type("K", (), {"save": lambda *a: None})()

    def _on_events(self, events, cause):
        self.dispatcher.handle(self.loop.engine, events, cause)

    def _fail_safes(self):
        return []


def test_an_active_behaviour_a_reload_removes_is_reported_released(monkeypatch):
    old = Engine(check_text(TEXT.format(1), os.path.join(ROOT, "s.rbs"), [LIB]), 0.0)
    reports = []
    monitor = FakeMonitor(old, reports)
    monitor._on_events(old.on_message("/x", 1.0, {"data": 5.0}), "test")
    monkeypatch.setattr(reloading, "ros_now", lambda: 2.0)
    new = Engine(check_text(TEXT.format(9), os.path.join(ROOT, "s.rbs"), [LIB]), 2.0)  # another condition
    monitor._swap(old, new, new.spec, {})
    assert [(r["event"], r["behaviour"], r["cause"]) for r in reports] == [
        ("start", 1, "deadline"), ("release", 1, "reload")]
