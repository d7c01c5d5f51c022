"""ClockStall (rubass/ros/clockjump.py): with use_sim_time, a /clock that stops is said once,
shown while it lasts, and its end is said; a clock that moves says nothing. Live:
test/integration/test_topics_clock_stall.py."""
import pytest

pytest.importorskip("rospy")

from rubass.ros.clockjump import ClockStall  # noqa: E402


class Clocks:
    def __init__(self):
        self.ros, self.wall = 100.0, 1000.0


def test_a_clock_that_stops_is_said_once_shown_while_it_lasts_and_its_end_is_said():
    c, logs = Clocks(), []
    stall = ClockStall(lambda: c.ros, lambda: c.wall, lambda level, text: logs.append((level, text)))
    for _ in range(40):  # moving: nothing
        c.ros += 0.25
        c.wall += 0.25
        stall.check()
    assert logs == [] and stall.stalled() == ""
    for _ in range(40):  # 10 s standing still
        c.wall += 0.25
        stall.check()
    assert [lvl for lvl, _ in logs] == ["warn"], logs
    assert "no /clock for 2.0 s" in logs[0][1] and "stands still at 110.000 s" in logs[0][1]
    assert stall.stalled().startswith("no /clock for 10.0 s")
    c.ros += 0.01
    assert stall.stalled() == "", "the first look after it moves sees it moving"
    stall.check()
    c.ros += 0.25
    c.wall += 0.25
    stall.check()
    assert [lvl for lvl, _ in logs] == ["warn", "info"] and "moves again" in logs[1][1], logs


def test_stalls_that_come_back_quickly_are_logged_at_most_every_ten_seconds():
    c, logs = Clocks(), []
    stall = ClockStall(lambda: c.ros, lambda: c.wall, lambda level, text: logs.append((level, text)))
    for _ in range(5):  # 2.5 s still, then a move, five times in 15 s
        for _ in range(10):
            c.wall += 0.25
            stall.check()
        c.ros += 0.1
        stall.check()
    warns = [t for lvl, t in logs if lvl == "warn"]
    assert len(warns) == 2, logs  # at 2 s and again 10 s later, not five times


def test_the_end_of_a_stall_is_said_when_the_status_sees_the_move_first_and_the_next_stall_is_said_too():
    """Review finding: when /diagnostics (stalled()) was the first to see the clock move, check() never
    said "moves again", and every later stall went unlogged."""
    c, logs = Clocks(), []
    stall = ClockStall(lambda: c.ros, lambda: c.wall, lambda level, text: logs.append((level, text)))
    for _ in range(12):  # 3 s standing still: said
        c.wall += 0.25
        stall.check()
    c.ros += 0.1
    assert stall.stalled() == ""  # the status looks first
    stall.check()
    for _ in range(60):  # 15 s later, a second stall
        c.wall += 0.25
        stall.check()
    assert [lvl for lvl, _ in logs] == ["warn", "info", "warn"], logs
