"""A serial board away while its action is active: the engine's holds (every tick) must not reopen
the port every tick ("failed action attempts" grew ~50/s); reopening follows the documented 0.5 s,
the away state is reported by periodic() twice a second, and the board gets its start when back."""
import time

import pytest

pytest.importorskip("serial")
pytest.importorskip("rospy")

from rubass.actions.base import Context  # noqa: E402
from rubass.actions.runner import ActionRunner  # noqa: E402
from rubass.lang.library import ActionDef  # noqa: E402
from rubass.ros.actions import serial_port  # noqa: E402
from test_serial_reconnect import board  # noqa: E402,F401  (the fake board: a pty behind a symlink)

CTX = Context(behaviour=1, line=3)


@pytest.fixture
def opens(monkeypatch):
    """Every attempt to open the port, by time."""
    times = []
    real = serial_port.serial.serial_for_url

    def counting(*args, **kw):
        times.append(time.monotonic())
        return real(*args, **kw)

    monkeypatch.setattr(serial_port.serial, "serial_for_url", counting)
    return times


@pytest.mark.parametrize("on_hold", [None, "H\n"])
def test_holds_while_the_board_is_away_reopen_at_the_documented_period_not_every_tick(board, opens, on_hold):
    board.plug()
    params = {"port": board.link, "baud": 115200, "write_timeout": 0.5, "on_start": "S\n", "on_release": "R\n"}
    if on_hold:
        params["on_hold"] = on_hold
    p = serial_port.SerialPlugin(ActionDef("board_stop", "serial", params))
    p.setup()
    r = ActionRunner(p, lambda level, text: None)
    r.start_thread()
    try:
        r.submit("start", CTX)
        assert board.read(0.3).startswith(b"S\n")
        board.unplug()
        t0 = time.monotonic()
        failures0 = r.stats.failures
        while time.monotonic() - t0 < 2.0:  # the engine's ticks: a hold every 20 ms (100 holds)
            r.submit("hold", CTX)
            time.sleep(0.02)
        away = [t for t in opens if t >= t0]
        # a hold once right after the write failed, then periodic() every 0.5 s (it was one per hold, ~100)
        assert 2 <= len(away) <= 7, len(away)
        # the failed write, then periodic()'s "is away while the action is active" every 0.5 s
        assert r.stats.failures - failures0 <= 7, r.stats.failures - failures0
        assert r.stats.failing, "the board that holds the stop is away: the action is failing"
        board.plug()
        got = board.read(1.5)
        assert got.startswith(b"S\n"), got  # back: the start first, once
        assert got.count(b"S\n") == 1
        end = time.monotonic() + 2
        while r.stats.failing and time.monotonic() < end:
            r.submit("hold", CTX)
            time.sleep(0.02)
        assert not r.stats.failing, r.stats.last_error
    finally:
        r.stop()
        p.close()
