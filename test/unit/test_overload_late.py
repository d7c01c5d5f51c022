"""The overload fail-safe starts on late reading as on dropped messages (rubass/actions/overload.py):
a monitor whose one receiving thread cannot keep up drops nothing, its messages wait in the
sockets' buffers, and the rules see the robot that late."""
from rubass.actions.overload import LATE, OverloadGuard


class Runner:
    def __init__(self):
        self.got = []

    def submit(self, kind, ctx):
        self.got.append(kind)


def guard():
    logs, events = [], []
    g = OverloadGuard(["stop"], 1.0, lambda level, text: logs.append((level, text)), events.append)
    return g, logs, events


def test_reading_late_starts_holds_and_releases_the_fail_safe_when_calm():
    g, logs, events = guard()
    runners = {"stop": Runner()}
    never = lambda name: False  # noqa: E731
    g.check(0, 10.0, runners, never, behind=LATE * 0.9)
    assert not g.active and not g.would_start(0, LATE * 0.9)
    assert g.would_start(0, LATE)
    g.check(0, 10.02, runners, never, behind=0.84)
    assert g.active and g.reason == "reading its topics 0.84 s late"
    assert logs == [("error", "overloaded: its topics are read 0.84 s late (their messages wait in the sockets' "
                              "buffers: it cannot keep up; a late message is evaluated as if it came now): running "
                              "the fail-safe actions stop (~overload_actions)")]
    g.check(0, 10.5, runners, never, behind=0.6)  # still late: held, not restarted
    g.check(0, 11.4, runners, never, behind=0.1)  # calm for 0.9 s only
    assert g.active
    g.check(0, 11.6, runners, never, behind=0.0)
    assert not g.active and runners["stop"].got == ["start", "hold", "hold", "release"]
    assert logs[-1] == ("warn", "overload over (no message dropped or read 0.5 s late for 1 s): releasing stop")
    assert [e["event"] for e in events] == ["start", "release"]


def test_drops_still_say_drops():
    g, logs, _ = guard()
    g.check(3, 10.0, {"stop": Runner()}, lambda name: False, {"/a": 3}, behind=0.9)
    assert g.reason == "dropping messages" and "3 messages dropped" in logs[0][1]


def test_without_fail_safe_actions_nothing_runs():
    logs = []
    g = OverloadGuard([], 1.0, lambda level, text: logs.append(text), lambda e: None)
    g.check(0, 10.0, {}, lambda name: False, behind=5.0)
    assert not g.active and logs == [] and not g.would_start(0, 5.0)
