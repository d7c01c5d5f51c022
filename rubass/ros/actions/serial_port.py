"""The `serial` plugin (pyserial): bytes on start, hold and release; the port is reopened after
the device vanishes (every 0.5 s while it stays away, not on every hold), and while the action is
active its start is written again on every reopen (a board that was away lost its state, whether
or not it had the start before)."""
from __future__ import annotations

import threading
from typing import Any, Optional

import rospy
import serial

from ...actions.base import ActionPlugin, ActionSetupError, Context, Skipped
from ...actions.status import NOTHING_DONE
from ...lang.libcheck import SERIAL_TEXT, serial_text_problem

REOPEN_PERIOD = 0.5


def _bytes(text: Optional[str]) -> Optional[bytes]:
    return None if text is None else text.encode("latin-1")  # checked at set-up: every character is a byte


class SerialPlugin(ActionPlugin):
    period = REOPEN_PERIOD

    def __init__(self, action: Any) -> None:
        super().__init__(action)
        self.port: Optional[serial.SerialBase] = None
        self.started = False  # the start bytes reached the port open now (reset when it closes)
        self.lock = threading.Lock()
        self.state = "closed"
        self.open_failed = False  # the latest attempt to open the port failed (then only periodic() retries)
        self.call_timeout = 2 * float(self.params.get("write_timeout") or 0.0)  # write, flush: the runner's stuck bound

    def setup(self) -> None:
        for key in SERIAL_TEXT:  # `rubass check` reports it at its place; a library loaded without it, here
            text = self.params.get(key)
            problem = serial_text_problem(text) if isinstance(text, str) else None
            if problem:
                raise ActionSetupError(f"action '{self.name}': '{key}': {problem}")
        self._open()  # a board that is not there yet is not fatal: periodic() keeps trying

    def _open(self) -> bool:
        try:
            self.port = serial.serial_for_url(self.params["port"], baudrate=self.params["baud"], timeout=0,
                                              write_timeout=self.params["write_timeout"])
            self.state = "open"
            self.started = False  # a new connection: the device knows nothing of earlier writes
            self.open_failed = False
            return True
        except (serial.SerialException, OSError, ValueError) as exc:
            self.port = None
            self.state = f"cannot open {self.params['port']}: {exc}"
            self.open_failed = True
            return False

    def _write(self, data: Optional[bytes]) -> Any:
        """Write now, opening the port if it is closed (a start or release, retried by the runner);
        NOTHING_DONE when there is nothing to write."""
        if not data:
            return NOTHING_DONE
        with self.lock:
            if self.port is None and not self._open():
                raise IOError(self.state)
            assert self.port is not None
            try:
                self.port.write(data)
                self.port.flush()
            except (serial.SerialException, OSError) as exc:
                self._drop(f"write failed: {exc}")
                raise IOError(self.state) from None

    def _drop(self, why: str) -> None:
        try:
            if self.port is not None:
                self.port.close()
        except (serial.SerialException, OSError):
            pass
        self.port = None
        self.started = False
        self.state = why

    def start(self, ctx: Context) -> Any:
        if self.started:  # periodic() wrote it already when the port came back: once, not twice
            return None
        done = self._write(_bytes(self.params.get("on_start")))
        self.started = self.port is not None
        return done

    def hold(self, ctx: Context) -> None:
        """A hold (every tick) reopens a vanished port once, at once (a glitch: the board is back before
        periodic() would look); after a failed attempt only periodic() reopens it, every REOPEN_PERIOD,
        and holds count no failure while the board is away: periodic() reports that (twice a second)."""
        with self.lock:
            if self.port is None and (self.open_failed or not self._open()):
                raise Skipped(f"serial board {self.params['port']} is away ({self.state})")
        self._catch_up()  # a hold may reopen the port before periodic() does: the start first
        self._write(_bytes(self.params.get("on_hold")))

    def release(self, ctx: Context) -> Any:
        self.started = False
        return self._write(_bytes(self.params.get("on_release")))

    def periodic(self) -> None:
        """Reopen a vanished device; while the action is active, write its start again to it."""
        with self.lock:
            reopened = self.port is None and self._open()
            if not reopened and self.port is not None and not self._alive():
                self._drop("the device went away")
        if self.port is None and self.active:  # an ERROR in /diagnostics (logged, counted) until it is back
            raise IOError(f"serial board {self.params['port']} is away ({self.state}) while the action is "
                          f"active: its start is written again when it returns")
        if self.port is not None:
            try:
                self._catch_up()
            except IOError:
                return  # dropped again: the next period reopens and tries again

    def _catch_up(self) -> None:
        """While active, a connection that has not had the start gets it (a board that came back,
        whichever of periodic() and hold() reopened it)."""
        data = _bytes(self.params.get("on_start"))
        if not (self.active and data and not self.started):
            return
        self._write(data)
        self.started = self.port is not None
        rospy.logwarn(f"action '{self.name}': serial board {self.params['port']} is back: start written again")

    def _alive(self) -> bool:
        """A pty or USB device that vanished shows as EIO/EOF on a non-blocking read."""
        try:
            assert self.port is not None
            self.port.in_waiting
            return True
        except (serial.SerialException, OSError):
            return False

    def close(self) -> None:
        with self.lock:
            self._drop("closed")
