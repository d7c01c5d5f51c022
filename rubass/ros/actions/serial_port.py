"""The `serial` plugin (pyserial): bytes on start, hold and release; the port is reopened after
the device vanishes, and a start that could not be written is written when it comes back."""
from __future__ import annotations

import threading
from typing import Any, Optional

import serial

from ...actions.base import ActionPlugin, Context

REOPEN_PERIOD = 0.5


def _bytes(text: Optional[str]) -> Optional[bytes]:
    return None if text is None else text.encode("latin-1", errors="replace")


class SerialPlugin(ActionPlugin):
    period = REOPEN_PERIOD

    def __init__(self, action: Any) -> None:
        super().__init__(action)
        self.port: Optional[serial.SerialBase] = None
        self.pending: Optional[bytes] = None  # start bytes owed to a device that was away
        self.lock = threading.Lock()
        self.state = "closed"

    def setup(self) -> None:
        self._open()  # a board that is not there yet is not fatal: periodic() keeps trying

    def _open(self) -> bool:
        try:
            self.port = serial.serial_for_url(self.params["port"], baudrate=self.params["baud"], timeout=0,
                                              write_timeout=self.params["write_timeout"])
            self.state = "open"
            return True
        except (serial.SerialException, OSError, ValueError) as exc:
            self.port = None
            self.state = f"cannot open {self.params['port']}: {exc}"
            return False

    def _write(self, data: Optional[bytes]) -> None:
        if not data:
            return
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
        self.state = why

    def start(self, ctx: Context) -> None:
        data = _bytes(self.params.get("on_start"))
        try:
            self._write(data)
            self.pending = None
        except IOError:
            self.pending = data
            raise

    def hold(self, ctx: Context) -> None:
        self._write(_bytes(self.params.get("on_hold")))

    def release(self, ctx: Context) -> None:
        self.pending = None
        self._write(_bytes(self.params.get("on_release")))

    def periodic(self) -> None:
        """Reopen a vanished device; deliver a start it missed while the action is still active."""
        with self.lock:
            if self.port is None:
                self._open()
            elif not self._alive():
                self._drop("the device went away")
        if self.port is not None and self.pending and self.active:
            try:
                self._write(self.pending)
                self.pending = None
            except IOError:
                pass

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
