"""No ~heartbeat at a tick where the monitor saw its messages LATE or later (rubass/ros/monitor.py,
_tick): a busy engine ticks between queued messages, so its beat went on at the full rate while
its rules ran seconds behind, feeding the robot's watchdog (a reviewer's finding: old loop 2 ticks
in 4 s, new 201, with 2.5 s of work queued)."""
from types import SimpleNamespace

import pytest

pytest.importorskip("rospy")

from rubass.actions.overload import LATE, OverloadGuard  # noqa: E402
from rubass.ros.monitor import Monitor  # noqa: E402


def monitor(waited, read=0.0, overload_actions=()):
    m = Monitor.__new__(Monitor)
    beats = []
    m.withheld = []
    m.outputs = SimpleNamespace(beat=beats.append)
    m.loop = SimpleNamespace(take_waited=lambda who=0: waited, dropped=0, dropped_by_topic={},
                             engine=SimpleNamespace(spec=SimpleNamespace(actions={})))
    m.watcher = SimpleNamespace(receiver=SimpleNamespace(take_behind=lambda who=0: read))
    m.overload = OverloadGuard(list(overload_actions), 1.0, lambda level, text: None, lambda event: None)
    m.keeper = SimpleNamespace(save=lambda *a: None, file=SimpleNamespace(error=None))
    m.dispatcher = SimpleNamespace(runners={}, orphans=[])
    m.clock_jump = SimpleNamespace(check=lambda engine, now: None)
    m.error_guard = SimpleNamespace(actions=[])
    return m, beats


@pytest.mark.parametrize("waited, read", [(0.0, 0.0), (LATE * 0.9, 0.0), (0.0, LATE * 0.9)])
def test_a_monitor_that_keeps_up_beats_at_every_tick(waited, read):
    m, beats = monitor(waited, read)
    m._tick(10.0)
    assert beats == [10.0]


@pytest.mark.parametrize("waited, read", [(LATE, 0.0), (2.5, 0.0), (0.0, 1.0)])
def test_a_monitor_that_sees_its_messages_late_does_not_beat(waited, read, monkeypatch):
    import rubass.ros.monitor as monitor_module

    warned = []
    monkeypatch.setattr(monitor_module.rospy, "logwarn_throttle", lambda period, text: warned.append(text))
    m, beats = monitor(waited, read)
    m._tick(10.0)
    assert beats == []
    assert warned and "no ~overload_actions are set; no ~heartbeat while it is late" in warned[0]
