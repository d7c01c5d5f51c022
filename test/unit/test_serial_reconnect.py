"""The serial plugin across a board that goes away and comes back (pty-based, no master): while the
action is active the start is written again on every reopen, exactly once, and nothing when inactive."""
import os
import select
import time

import pytest

pytest.importorskip("serial")
pytest.importorskip("rospy")

from rubass.actions.base import Context  # noqa: E402
from rubass.actions.runner import ActionRunner  # noqa: E402
from rubass.lang.library import ActionDef  # noqa: E402
from rubass.ros.actions.serial_port import SerialPlugin  # noqa: E402

CTX = Context(behaviour=1, line=3)


class Board:
    """A pty whose slave is reached through a symlink, as udev's /dev/serial/by-id/… link."""

    def __init__(self, link):
        self.link = link
        self.master = None

    def plug(self):
        self.master, self.slave = os.openpty()
        if os.path.islink(self.link):
            os.unlink(self.link)
        os.symlink(os.ttyname(self.slave), self.link)

    def unplug(self):
        if self.master is not None:
            os.close(self.master)
            os.close(self.slave)
            os.unlink(self.link)
            self.master = None

    def read(self, seconds):
        got, end = b"", time.monotonic() + seconds
        while time.monotonic() < end:
            if select.select([self.master], [], [], 0.05)[0]:
                got += os.read(self.master, 100)
        return got


@pytest.fixture
def board(tmp_path):
    b = Board(str(tmp_path / "ttyBOARD"))
    yield b
    b.unplug()


def plugin(board):
    p = SerialPlugin(ActionDef("board_stop", "serial", {"port": board.link, "baud": 115200, "write_timeout": 0.5,
                                                        "on_start": "S\n", "on_release": "R\n"}))
    p.setup()
    return p


def away_and_back(board, p):
    board.unplug()
    for _ in range(3):  # the plugin notices the device is gone; it cannot reopen it yet
        if p.active:  # a failure (/diagnostics ERROR) while the board that holds the stop is away
            with pytest.raises(IOError, match="is away .* while the action is active"):
                p.periodic()
        else:
            p.periodic()
    assert p.port is None
    board.plug()
    p.periodic()


def test_a_board_unplugged_while_its_stop_is_active_gets_the_start_again_when_it_returns(board):
    board.plug()
    p = plugin(board)
    try:
        p.active = True
        p.start(CTX)
        assert board.read(0.2) == b"S\n"
        away_and_back(board, p)
        assert board.read(0.3) == b"S\n"  # the power-cycled board lost its state: the start again
        p.periodic()
        assert board.read(0.2) == b"", "written once per reopen, not every period"
        away_and_back(board, p)
        assert board.read(0.3) == b"S\n", "and again on every reopen while active"
        p.active = False
        p.release(CTX)
        assert board.read(0.2) == b"R\n"
    finally:
        p.close()


def test_a_board_that_returns_while_the_action_is_inactive_gets_nothing(board):
    board.plug()
    p = plugin(board)
    try:
        p.active = True
        p.start(CTX)
        p.active = False
        p.release(CTX)
        assert board.read(0.2) == b"S\nR\n"
        away_and_back(board, p)
        assert board.read(0.3) == b""
    finally:
        p.close()


def test_a_board_that_returns_after_a_failed_start_gets_the_start_once(board):
    """The runner retries a failed start while periodic() reopens the port: whichever comes first
    writes it, the other nothing (the board got 'S\\nS\\n')."""
    p = plugin(board)  # the board is not there yet
    try:
        p.active = True
        with pytest.raises(IOError):
            p.start(CTX)
        board.plug()
        p.periodic()  # reopened: the start is written
        p.start(CTX)  # the runner's retry of the failed start
        assert board.read(0.3) == b"S\n"
        p.active = False
        p.release(CTX)
        assert board.read(0.2) == b"R\n"
    finally:
        p.close()


def test_a_failed_start_retried_by_the_runner_reaches_the_board_once_when_it_is_plugged_in(board):
    p = plugin(board)
    runner = ActionRunner(p, lambda level, text: None)
    runner.start_thread()
    try:
        runner.submit("start", CTX)
        deadline = time.monotonic() + 5
        while not runner.stats.failures and time.monotonic() < deadline:
            time.sleep(0.02)
        assert runner.stats.failures, "the start failed while the board was away"
        board.plug()
        assert board.read(2.5) == b"S\n"  # a reopen period and the longest retry backoff (1 s), then some
    finally:
        runner.stop()
        p.close()


def test_a_board_with_hold_bytes_that_a_hold_reopens_gets_the_start_before_the_hold(board):
    """Review finding: with `on_hold`, a hold (50 Hz while active) reopened the port before
    periodic() (every 0.5 s) and wrote only the hold; the start was never written again."""
    board.plug()
    p = SerialPlugin(ActionDef("board_stop", "serial", {"port": board.link, "baud": 115200, "write_timeout": 0.5,
                                                        "on_start": "S\n", "on_hold": "H\n", "on_release": "R\n"}))
    p.setup()
    try:
        p.active = True
        p.start(CTX)
        p.hold(CTX)
        assert board.read(0.2) == b"S\nH\n"
        board.unplug()
        with pytest.raises(IOError):
            p.hold(CTX)  # the write fails: the device is gone
        board.plug()
        p.hold(CTX)  # reopens the port before any periodic()
        assert board.read(0.3) == b"S\nH\n"
        p.periodic()
        p.hold(CTX)
        assert board.read(0.2) == b"H\n", "the start once per connection"
    finally:
        p.close()
