"""A reload that renames a behaviour, or changes its actions, while its stop is on: the stop goes on.

Found by an acceptance sweep: an unnamed behaviour given one more action (or a renamed one) was a
behaviour the reload removed plus a new one, and the old one's release reached the serial board
before the new one's start ("R" then "S" while the speed was still over the limit); a renamed
behaviour's `for` counted again from the reload (a stop a `for` time late), and a renamed
`within`'s minimum hold was cut short at the reload."""
import os

import pytest

pytest.importorskip("rospy")

from rubass.actions.base import ActionPlugin  # noqa: E402
from rubass.actions.dispatch import Dispatcher  # noqa: E402
from rubass.actions.runner import ActionRunner  # noqa: E402
from rubass.engine import Engine  # noqa: E402
from rubass.lang import check_text  # noqa: E402
from rubass.lang.library import ActionDef  # noqa: E402
from rubass.ros import reloading  # noqa: E402

from conftest import ROOT  # noqa: E402

LIB = os.path.join(ROOT, "docs", "examples", "actions.yaml")
HEAD = "action primitive board_stop, warn;\nentity e { rules: fast: topic /v.data > 0.5; }\n"


def spec(text):
    return check_text(HEAD + text, os.path.join(ROOT, "s.rbs"), [LIB])


class Board(ActionPlugin):
    """What a serial board would read: S on start, R on release."""

    def __init__(self, name, per_behaviour=False):
        super().__init__(ActionDef(name, "fake:Fake", {}))
        self.per_behaviour = per_behaviour


def phases(runner):
    return [kind for kind, _ in runner._queue]  # what the runner's thread would send, in order


class Monitor(reloading.Reloading):
    """The real swap, dispatcher and runners (their threads not started: their queues are read)."""

    def __init__(self, engine, runners):
        from rubass.ros.clockjump import ClockJump

        self.loop = type("Loop", (), {"engine": engine})()
        self.dispatcher = Dispatcher(runners, lambda record: self.records.append(record), lambda: 0.0)
        self.keeper = type("K", (), {"save": lambda *a: None})()
        self.clock_jump = ClockJump(self.dispatcher, lambda level, text: None, lambda engine: None)
        self.records = []

    def _on_events(self, events, cause):
        events = self.clock_jump.take_over(self.loop.engine, events)  # as Monitor._on_events
        self.dispatcher.handle(self.loop.engine, events, cause)

    def _fail_safes(self):
        return []


def run_to(engine, monitor, t):
    monitor._on_events(engine.advance(t), "deadline")


def swap(monitor, monkeypatch, new_text, t, runners):
    monkeypatch.setattr(reloading, "ros_now", lambda: t)
    old = monitor.loop.engine
    new = Engine(spec(new_text), t)
    monitor._swap(old, new, new.spec, runners)
    return new


def start(text, runners, messages):
    engine = Engine(spec(text), 0.0)
    engine.evaluate_all(0.0)
    monitor = Monitor(engine, runners)
    for t, v in messages:
        monitor._on_events(engine.on_message("/v", t, {"data": v}), "message")
    return engine, monitor


@pytest.mark.parametrize("new_text", [
    "if (e.fast) then { board_stop; warn; }\n",  # unnamed, one more action
    "halt: if (e.fast) then { board_stop; }\n",  # named now
])
def test_an_edit_that_makes_an_active_stop_another_behaviour_never_releases_the_board(monkeypatch, new_text):
    board, warn = ActionRunner(Board("board_stop"), print), ActionRunner(Board("warn", True), print)
    runners = {"board_stop": board, "warn": warn}
    _, monitor = start("if (e.fast) then { board_stop; }\n", runners, [(1.0, 0.6)])
    assert phases(board) == ["start"]
    new = swap(monitor, monkeypatch, new_text, 2.0, runners)
    assert new.active_behaviours() == [1]
    assert phases(board) == ["start"], "the board read R then S at the reload, with the speed still over"
    assert board.active
    kinds = [(r["event"], r.get("name", "")) for r in monitor.records]
    # ~events: the old one's release before the new one's start, so pairing by number ends "on"
    assert kinds[-2:] == [("release", ""), ("start", new.spec.behaviours[0].name)]
    monitor._on_events(new.on_message("/v", 3.0, {"data": 0.0}), "message")
    assert phases(board) == ["start", "release"] and not board.active


def test_a_renamed_behaviour_whose_action_changed_definition_still_goes_on(monkeypatch):
    old_board = ActionRunner(Board("board_stop"), print)
    _, monitor = start("bstop: if (e.fast) then { board_stop; }\n", {"board_stop": old_board}, [(1.0, 0.6)])
    new_board = ActionRunner(Board("board_stop"), print)  # a reload that also changed its library entry
    swap(monitor, monkeypatch, "halt: if (e.fast) then { board_stop; }\n", 2.0, {"board_stop": new_board})
    assert phases(new_board) == ["start"] and new_board.active  # the new definition takes over, once
    assert phases(old_board) == ["start"]  # the old one is not released before the new one starts


def test_a_behaviour_that_goes_is_still_released_also_when_its_action_went_with_it(monkeypatch):
    board, warn = ActionRunner(Board("board_stop"), print), ActionRunner(Board("warn", True), print)
    _, monitor = start("if (e.fast) then { board_stop; warn; }\n", {"board_stop": board, "warn": warn}, [(1.0, 0.6)])
    swap(monitor, monkeypatch, "if (e.fast) then { warn; }\n", 2.0, {"warn": warn})
    assert phases(board) == ["start", "release"], "the old runner of an action no spec names releases it"
    assert phases(warn) == ["start", "start", "release"]  # a log: the old behaviour's release, the new's start


def test_a_log_action_whose_definition_changed_logs_no_start_for_a_behaviour_the_reload_removes(monkeypatch):
    warn = ActionRunner(Board("warn", True), print)
    _, monitor = start("if (e.fast) then { warn; }\n", {"warn": warn}, [(1.0, 0.6)])
    new_warn = ActionRunner(Board("warn", True), print)
    swap(monitor, monkeypatch, "slow: if (topic /v.data > 9) then { warn; }\n", 2.0, {"warn": new_warn})
    assert phases(new_warn) == ["release"]


def test_a_renamed_behaviour_keeps_its_for_count(monkeypatch):
    old_text = "bstop: if (e.fast for 2 s) then { board_stop; }\n"
    board = ActionRunner(Board("board_stop"), print)
    old, monitor = start(old_text, {"board_stop": board}, [(1.0, 0.6)])
    new = swap(monitor, monkeypatch, old_text.replace("bstop", "overspeed"), 1.5, {"board_stop": board})
    assert new.active_behaviours() == []
    assert new.next_deadline() == pytest.approx(3.0)  # not 3.5: the count since 1.0 is kept
    run_to(new, monitor, 3.0)
    assert new.active_behaviours() == [1] and phases(board) == ["start"]


def test_a_renamed_behaviour_keeps_its_within_hold(monkeypatch):
    old_text = "bw: if (e.fast within 2 s) then { board_stop; }\n"
    board = ActionRunner(Board("board_stop"), print)
    _, monitor = start(old_text, {"board_stop": board}, [(1.0, 0.6), (1.5, 0.0)])
    new = swap(monitor, monkeypatch, old_text.replace("bw:", "hold_w:"), 2.0, {"board_stop": board})
    assert new.active_behaviours() == [1], "the minimum hold was cut short by a rename"
    assert phases(board) == ["start"]
    run_to(new, monitor, 3.49)
    assert new.active_behaviours() == [1]
    run_to(new, monitor, 3.5)
    assert new.active_behaviours() == [] and phases(board) == ["start", "release"]


def test_a_new_behaviour_with_another_condition_counts_from_the_reload(monkeypatch):
    board = ActionRunner(Board("board_stop"), print)
    _, monitor = start("bstop: if (e.fast for 2 s) then { board_stop; }\n", {"board_stop": board}, [(1.0, 0.6)])
    new = swap(monitor, monkeypatch, "other: if (e.fast for 3 s) then { board_stop; }\n", 1.5, {"board_stop": board})
    assert new.next_deadline() == pytest.approx(4.5)  # another condition: no history taken


@pytest.mark.parametrize("entity, rule", [("e", "hot2"), ("base", "hot")])  # the rule renamed, its entity renamed
def test_a_renamed_rule_keeps_its_value_and_its_for(monkeypatch, entity, rule):
    """An acceptance sweep: renaming a rule (or its entity) whose `for` held released the stop at the
    reload for the whole `for` time, and a creep took the base meanwhile."""
    text = ("action primitive board_stop, warn;\nentity {} {{ rules: {}: (topic /v.data > 0.5) for 0.5 s; }}\n"
            "halt: if ({}.{}) then {{ board_stop; }}\n")
    board = ActionRunner(Board("board_stop"), print)
    engine = Engine(check_text(text.format("e", "hot", "e", "hot"), os.path.join(ROOT, "s.rbs"), [LIB]), 0.0)
    engine.evaluate_all(0.0)
    monitor = Monitor(engine, {"board_stop": board})
    monitor._on_events(engine.on_message("/v", 1.0, {"data": 0.6}), "message")
    run_to(engine, monitor, 1.5)
    assert phases(board) == ["start"]
    monkeypatch.setattr(reloading, "ros_now", lambda: 2.0)
    new = Engine(check_text(text.format(entity, rule, entity, rule), os.path.join(ROOT, "s.rbs"), [LIB]), 2.0)
    monitor._swap(engine, new, new.spec, {"board_stop": board})
    assert new.active_behaviours() == [1] and phases(board) == ["start"], "released at the reload"


def test_a_renamed_rule_with_a_for_keeps_its_count(monkeypatch):
    head = "action primitive board_stop, warn;\nentity e {{ rules: {}: (topic /v.data > 0.5) for 2 s; }}\n"
    text = "halt: if (e.{}) then {{ board_stop; }}\n"
    engine = Engine(check_text(head.format("hot") + text.format("hot"), os.path.join(ROOT, "s.rbs"), [LIB]), 0.0)
    engine.evaluate_all(0.0)
    engine.on_message("/v", 1.0, {"data": 0.6})
    new = Engine(check_text(head.format("hot2") + text.format("hot2"), os.path.join(ROOT, "s.rbs"), [LIB]), 1.5)
    new.adopt(engine, 1.5)
    assert new.next_deadline() == pytest.approx(3.0)  # counted since 1.0, not from the reload


def test_a_stop_whose_definition_a_reload_changed_keeps_its_topic_from_a_lower_action():
    """An acceptance sweep: a reload changing a held stop's `rate` let a creep (priority 1, same topic)
    publish once: the old stop left its seat before the new one had started, and the arbiter handed
    the topic to the creep. The new runner claims the topic as it adopts the old one's holders."""
    from rubass.actions.arbitration import Arbiter
    from rubass.actions.base import Context

    arbiter, handed = Arbiter(), []
    old_stop, new_stop, crawl = Board("stop"), Board("stop"), Board("crawl")
    old_stop.seat = arbiter.seat("/base", "stop", 3, lambda: handed.append("old stop"))
    crawl.seat = arbiter.seat("/base", "crawl", 1, lambda: handed.append("crawl"))
    old_stop.seat.activate()
    crawl.seat.activate()  # active under the stop, waiting
    new_stop.seat = arbiter.seat("/base", "stop", 3, lambda: handed.append("new stop"))  # built by the reload
    old, new = ActionRunner(old_stop, print), ActionRunner(new_stop, print)
    old.submit("start", Context(1, 3, key=("sig", 1)))
    new.adopt(old)
    old_stop.seat.leave()  # the reload closes the runner it dropped
    assert "crawl" not in handed, "the creep got the base between the two stops"
    assert arbiter.owner("/base") is new_stop.seat and handed == ["new stop"]


@pytest.mark.parametrize("behaviour", ["halt: if ({ent}.hot) then {{ board_stop; }}",  # a rule using a sibling
                                       "if ({ent}.fast for 0.5 s) then {{ board_stop; }}"])  # unnamed, its own for
def test_an_entity_renamed_keeps_the_for_of_rules_using_their_siblings(monkeypatch, behaviour):
    """The review: renaming an entity changed the signature of every rule that uses a sibling (`e.fast`
    became `base.fast` in it), and the text of an unnamed behaviour's condition: the stop was released
    at the reload for its `for` time. Renamed keys are read under their new names before comparing."""
    text = ("action primitive board_stop, warn;\nentity {ent} {{ rules: fast: topic /v.data > 0.5; "
            "hot: fast for 0.5 s; }}\n" + behaviour + "\n")
    board = ActionRunner(Board("board_stop"), print)
    engine = Engine(check_text(text.format(ent="e"), os.path.join(ROOT, "s.rbs"), [LIB]), 0.0)
    engine.evaluate_all(0.0)
    monitor = Monitor(engine, {"board_stop": board})
    monitor._on_events(engine.on_message("/v", 1.0, {"data": 0.6}), "message")
    run_to(engine, monitor, 1.5)
    assert phases(board) == ["start"]
    monkeypatch.setattr(reloading, "ros_now", lambda: 2.0)
    new = Engine(check_text(text.format(ent="base"), os.path.join(ROOT, "s.rbs"), [LIB]), 2.0)
    monitor._swap(engine, new, new.spec, {"board_stop": board})
    assert new.active_behaviours() == [1] and phases(board) == ["start"], "released at the reload"


def test_a_renamed_key_is_replaced_only_as_a_whole_name():
    from rubass.engine.handover import _renamer

    rename = _renamer({"e.fast": "base.fast"})
    assert rename("e.fast for 0.5 [e.fast: topic /e.fast > 1]") == "base.fast for 0.5 [base.fast: topic /e.fast > 1]"
    assert rename("e.faster or te.fast or topic /x.e.fast") == "e.faster or te.fast or topic /x.e.fast"


EDITS = {  # the rule given a minimum hold (operators added); the `for` moved into the behaviour
    "within": ("entity e { rules: high: ((topic /v.data > 1) for 1 s) within 2 s; }\n", "halt: if (e.high)"),
    "moved": ("entity e { rules: high: topic /v.data > 1; }\n", "halt: if (e.high for 1 s)"),
}


def _held_stop(monkeypatch, edit, later):
    """A stop on `high: (v > 1) for 1 s` since 2.0 s, reloaded at 3.0 s with `edit`; `later`: the
    values of /v after the reload. The board's phases, and the last record's event and cause."""
    head = "action primitive board_stop, warn;\n"
    text = head + "entity e { rules: high: (topic /v.data > 1) for 1 s; }\nhalt: if (e.high) then { board_stop; }\n"
    board = ActionRunner(Board("board_stop"), print)
    engine = Engine(check_text(text, os.path.join(ROOT, "s.rbs"), [LIB]), 0.0)
    engine.evaluate_all(0.0)
    monitor = Monitor(engine, {"board_stop": board})
    monitor._on_events(engine.on_message("/v", 1.0, {"data": 2.0}), "message")
    run_to(engine, monitor, 2.5)
    assert phases(board) == ["start"]
    monkeypatch.setattr(reloading, "ros_now", lambda: 3.0)
    rule, cond = EDITS[edit]
    new = Engine(check_text(head + rule + cond + " then { board_stop; }\n", os.path.join(ROOT, "s.rbs"), [LIB]), 3.0)
    monitor._swap(engine, new, new.spec, {"board_stop": board})
    assert phases(board) == ["start"], "released at the reload, with the speed still over the limit"
    for t, v in later:
        run_to(new, monitor, t)
        monitor.clock_jump.check(new, t)  # the monitor's tick
        monitor._on_events(new.on_message("/v", t, {"data": v}), "message")
    for t in (4.49, 4.5, 5.0, 5.49, 5.5, 6.0):
        run_to(new, monitor, t)
        monitor.clock_jump.check(new, t)
    return board, new, monitor


@pytest.mark.parametrize("edit", sorted(EDITS))
def test_an_edit_that_restarts_a_held_conditions_for_does_not_release_its_stop(monkeypatch, edit):
    """The re-sweep of reloads: adding a minimum hold to a held rule (`… within 2 s`), or moving its
    `for` into the behaviour, made it read false until its new `for` elapsed: the stop was released at
    the reload and a creep took the base for a second. It is held until its condition could hold again,
    and the engine owns it again, with no second start, when it does."""
    board, new, monitor = _held_stop(monkeypatch, edit, [(3.5, 2.0), (4.2, 2.0)])
    assert [p for p in phases(board) if p != "hold"] == ["start"] and board.active  # the start became a hold
    assert new.active_behaviours() == [1] and not monitor.clock_jump.carried
    assert [r["event"] for r in monitor.records] == ["start"], "no second start, no release in ~events"


@pytest.mark.parametrize("edit", sorted(EDITS))
def test_a_stop_held_over_a_reload_is_released_when_its_condition_could_have_held_again(monkeypatch, edit):
    board, new, monitor = _held_stop(monkeypatch, edit, [(3.2, 0.0)])
    assert phases(board) == ["start", "release"] and not board.active
    assert new.active_behaviours() == [] and not new.active_actions()
    assert [(r["event"], r["cause"]) for r in monitor.records][-1] == ("release", "deadline")
    longest = {"within": 2.0, "moved": 1.0}[edit]
    assert monitor.records[-1]["time"] == pytest.approx(3.0 + longest + 0.5)  # the spec's longest window + 0.5 s
