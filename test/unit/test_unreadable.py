"""A message none of whose fields the spec can read (a publisher of another type on the sensor's
topic: a Float32 on /scan) is no data: its fields read unknown, and age() and frequency() go on
counting from the last readable message, so a dead laser beside it still trips its age guard (an
acceptance finding: the Float32s kept age(/scan) fresh for good)."""
from rubass.engine import Engine
from rubass.engine.values import UNREADABLE
from rubass.lang import check_text

SPEC = """action primitive stop;
entity laser {
  rules:
    near: topic /scan.data < 0.5;
    stale: age(topic /scan) > 0.5 s;
    slow: frequency(topic /scan) < 5 Hz;
}
if (laser.near or laser.stale) then { stop; }
"""
LIB = "actions:\n  stop: {plugin: log, level: warn}\n"


def _engine(write):
    spec = check_text(SPEC, "s.rbs", [write("lib.yaml", LIB)])
    engine = Engine(spec, 0.0)
    engine.evaluate_all(0.0)
    return engine


def test_unreadable_messages_leave_age_counting_and_the_fields_unknown(write):
    engine = _engine(write)
    engine.on_message("/scan", 0.1, {"data": 3.0})
    assert engine.store.rules["laser.near"] is False
    events = []
    for i in range(1, 10):  # the laser died at 0.1; another type's publisher goes on at 10 Hz
        events += engine.on_message("/scan", 0.1 + 0.1 * i, UNREADABLE)
    assert engine.rule_value("laser.near") is not False  # unknown: no value could be read
    stale = [e for e in events if e.rule == "laser.stale" and e.value is True]
    assert stale and abs(stale[0].time - 0.6) < 1e-5, events  # 0.5 s after the last readable message (> : 1 µs on)
    assert [e for e in events if e.kind == "start"]


def test_a_readable_message_is_data_again(write):
    engine = _engine(write)
    engine.on_message("/scan", 0.1, {"data": 3.0})
    engine.on_message("/scan", 0.3, UNREADABLE)
    engine.on_message("/scan", 0.5, {"data": 3.0})
    engine.advance(0.9)
    assert engine.rule_value("laser.stale") is False  # 0.4 s after the readable one at 0.5


def test_unreadable_messages_leave_stamp_age_counting(write):
    """Review: the stamp was set unknown by an unreadable message, so a stamp_age guard never tripped."""
    spec = check_text("action primitive stop;\nentity laser { rules: near: topic /scan.range_min < 0.5; "
                      "stale: stamp_age(topic /scan) > 0.5 s; }\nif (laser.near or laser.stale) then { stop; }\n",
                      "s.rbs", [write("lib.yaml", LIB)])
    engine = Engine(spec, 0.0)
    engine.evaluate_all(0.0)
    engine.on_message("/scan", 0.1, _Scan(0.1, 3.0))
    events = []
    for i in range(1, 10):
        events += engine.on_message("/scan", 0.1 + 0.1 * i, UNREADABLE)
    events += engine.advance(3.0)
    assert [e for e in events if e.rule == "laser.stale" and e.value is True], events
    assert [e for e in events if e.kind == "start"]


class _Stamp:
    def __init__(self, t):
        self.t = t

    def to_sec(self):
        return self.t


class _Header:
    def __init__(self, t):
        self.stamp = _Stamp(t)


class _Scan:
    def __init__(self, t, range_min):
        self.header, self.range_min = _Header(t), range_min
