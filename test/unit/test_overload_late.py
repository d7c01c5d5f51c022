"""The overload fail-safe starts on late messages as on dropped ones (rubass/actions/overload.py):
a monitor that cannot keep up drops nothing until its queue is full: its messages wait in the
sockets' buffers (its receiving thread reads late) or in the engine's queue (its engine evaluates
late), and the rules see the robot, and act, that late."""
from rubass.actions.overload import LATE, QUEUE, OverloadGuard, late_status


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


def test_messages_waiting_in_the_engines_queue_start_the_fail_safe_and_say_so():
    g, logs, events = guard()
    runners = {"stop": Runner()}
    g.check(0, 10.0, runners, lambda name: False, behind=0.94, where=QUEUE)
    assert g.active and g.reason == "evaluating its messages 0.94 s late"
    assert logs == [("error", "overloaded: its messages are evaluated 0.94 s late (they wait in the engine's queue: "
                              "it cannot keep up; its actions come that late): running the fail-safe actions stop "
                              "(~overload_actions)")]
    assert runners["stop"].got == ["start"]


def test_the_status_names_the_later_of_the_sockets_and_the_queue():
    assert late_status(0.0, 0.0) == "no"
    assert late_status(LATE * 0.99, LATE * 0.99) == "no"
    assert late_status(0.7, 0.2) == ("0.70 s (messages waited that long in the sockets' buffers: the monitor cannot "
                                     "keep up)")
    assert late_status(0.2, 1.25) == ("1.25 s (messages waited that long in the engine's queue: the monitor cannot "
                                      "keep up)")
