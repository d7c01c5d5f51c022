"""MasterWatch.check (rubass/ros/master_watch.py) against a scripted master: when it registers
everything again. The real master restarts are in test/integration/test_faults.py."""
from rubass.ros import master_watch
from rubass.ros.master_watch import MasterWatch, Registered

ME = "http://host:4000/"


class ScriptedMaster:
    """Answers lookupNode and getPid from `polls`: (known uri or None, pid), or an OSError."""

    def __init__(self, polls):
        self.polls = list(polls)
        self.answer = None

    def call(self, method, *params):
        if method == "lookupNode":
            self.answer = self.polls.pop(0)
            if isinstance(self.answer, Exception):
                raise self.answer
            uri = self.answer[0]
            return (1, "", uri) if uri else (-1, "unknown node", "")
        assert method == "getPid"
        return 1, "", self.answer[1]

    def close(self):
        pass


def run(monkeypatch, polls, fail=()):
    """The result of each poll, and after which polls everything was registered again."""
    watch = MasterWatch("/rubass", ME, "http://master:11311", 0.25, lambda level, text: None)
    watch._caller = ScriptedMaster(polls)
    registered, results = [], []

    def register_all(master, caller_id, node_uri):
        if len(results) in fail:
            raise IOError("refused")
        registered.append(len(results))
        return Registered(1, 1, 1, 1.0)

    monkeypatch.setattr(master_watch, "register_all", register_all)
    for _ in polls:
        try:
            results.append(watch.check())
        except IOError:
            results.append("failed")
    return results, registered, watch


def test_the_first_poll_registers_everything_once_then_a_steady_master_is_left_alone(monkeypatch):
    results, registered, watch = run(monkeypatch, [(ME, 7), (ME, 7), (ME, 7)])
    assert results == ["ok", "ok", "ok"] and registered == [0]
    assert watch.reregistrations == 0 and watch.state == "connected"


def test_a_master_that_forgot_the_node_gets_everything_again(monkeypatch):
    results, registered, watch = run(monkeypatch, [(ME, 7), (None, 7), (ME, 7)])
    assert results == ["ok", "re-registered", "ok"] and registered == [0, 1]
    assert watch.reregistrations == 1


def test_after_an_outage_everything_is_registered_again_even_when_the_master_knows_the_node(monkeypatch):
    # rospy retried one registration made during the outage: the new master knows the node
    polls = [(ME, 7), OSError("refused"), OSError("refused"), (ME, 7), (ME, 7)]
    results, registered, watch = run(monkeypatch, polls)
    assert results == ["ok", "unreachable", "unreachable", "re-registered", "ok"]
    assert registered == [0, 3] and watch.down_since is None


def test_a_master_process_that_changed_between_two_polls_gets_everything_again(monkeypatch):
    results, registered, _ = run(monkeypatch, [(ME, 7), (ME, 8), (ME, 8)])
    assert results == ["ok", "re-registered", "ok"] and registered == [0, 1]


def test_a_refused_registration_is_tried_again_at_the_next_poll(monkeypatch):
    results, registered, watch = run(monkeypatch, [(ME, 7), (ME, 8), (ME, 8), (ME, 8)], fail={1})
    assert results == ["ok", "failed", "re-registered", "ok"] and registered == [0, 2]
    results, registered, watch = run(monkeypatch, [(ME, 7), OSError("down"), (ME, 7), (ME, 7), (ME, 7)], fail={2})
    assert results == ["ok", "unreachable", "failed", "re-registered", "ok"] and registered == [0, 3]


def test_another_node_holding_our_name_is_not_fought_over(monkeypatch):
    results, registered, watch = run(monkeypatch, [(ME, 7), ("http://other:5000/", 7)])
    assert results == ["ok", "foreign"] and registered == [0]
    assert "holds the name" in watch.state


def test_an_unreachable_master_is_reported_with_how_long(monkeypatch):
    results, registered, watch = run(monkeypatch, [OSError("down")] * 3)
    assert results == ["unreachable"] * 3 and registered == []
    assert watch.state.startswith("unreachable for")


def test_the_state_says_unreachable_before_the_log_line_is_written():
    """Acceptance finding (two network namespaces): with the master's host cut off, rospy's log
    call blocked until the link was back, and the state, set after it, read 'connected' all along."""
    states = []
    watch = MasterWatch("/rubass", ME, "http://master:11311", 0.25,
                        lambda level, text: states.append(watch.state))  # what /diagnostics reads while it logs
    watch._caller = ScriptedMaster([OSError("timed out")])
    assert watch.check() == "unreachable"
    assert len(states) == 1 and states[0].startswith("unreachable for"), states


def test_a_master_lost_during_the_registration_is_unreachable_not_an_error(monkeypatch):
    """A re-sweep: the master died while the first poll registered everything: `master watch:
    ConnectionRefusedError` was logged as an ERROR, and nothing said the master was down."""
    lines = []
    watch = MasterWatch("/rubass", ME, "http://master:11311", 0.25, lambda level, text: lines.append((level, text)),
                        unreachable=lambda: "STARTING")
    watch._caller = ScriptedMaster([(ME, 7), (ME, 7)])
    calls = []

    def register_all(master, caller_id, node_uri):
        calls.append(1)
        if len(calls) == 1:
            raise ConnectionRefusedError(111, "Connection refused")
        return Registered(1, 1, 1, 1.0)

    monkeypatch.setattr(master_watch, "register_all", register_all)
    assert watch.check() == "unreachable" and watch.state.startswith("unreachable for")
    assert lines == [("warn", "the master at http://master:11311 cannot be reached ([Errno 111] Connection refused): "
                              "STARTING")]
    assert watch.check() == "re-registered" and watch.state == "connected"  # it is back: all of it again


def test_the_monitor_says_it_enforces_nothing_until_its_engine_runs():
    """A re-sweep: the warning said "the rules keep being enforced" for the second between the engine's
    creation and its thread's start (while the topics were subscribed, with the master down)."""
    from types import SimpleNamespace

    from rubass.ros.monitor import Monitor

    means = Monitor._unreachable_means
    assert means(SimpleNamespace(enforcing=False, loop=object(), load_error="")) == \
        master_watch.MONITOR_STARTING_UNREACHABLE
    assert means(SimpleNamespace(enforcing=False, loop=None, load_error="s.rbs:1:1: error")).startswith(
        "NO RULE IS ENFORCED (the spec cannot be used")
    assert means(SimpleNamespace(enforcing=True, loop=object(), load_error="")) == master_watch.MONITOR_UNREACHABLE
