"""The acceptance repro of a serial safety board that is unplugged while its stop is active
(socat's linked ptys, as a USB board re-enumerated under its udev link): when it returns it gets
the start again, once, and /diagnostics is OK again."""
import os
import select
import shutil
import subprocess
import time

import pytest

from rosharness import LIB, spec, wait_log

pytestmark = [pytest.mark.ros, pytest.mark.slow]


class Socat:
    def __init__(self, tmp_path):
        self.board, self.host = str(tmp_path / "ttyBOARD"), str(tmp_path / "ttyHOST")
        self.proc = None
        self.fd = None

    def start(self):
        self.proc = subprocess.Popen(["socat", f"pty,raw,echo=0,link={self.board}",
                                      f"pty,raw,echo=0,link={self.host}"], stderr=subprocess.DEVNULL)
        end = time.time() + 5
        while not (os.path.exists(self.board) and os.path.exists(self.host)):
            assert time.time() < end and self.proc.poll() is None, "socat did not make its ptys"
            time.sleep(0.02)
        self.fd = os.open(self.host, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)

    def stop(self):
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None
        if self.proc is not None and self.proc.poll() is None:
            self.proc.terminate()
            self.proc.wait(5)
        self.proc = None

    def read(self, seconds, until=None):
        """What the board got within `seconds`; with `until`, 0.3 s more once that came (a repeat)."""
        got, end = b"", time.time() + seconds
        while time.time() < end:
            if until is not None and got.endswith(until):
                end, until = min(end, time.time() + 0.3), None
            if select.select([self.fd], [], [], 0.05)[0]:
                try:
                    got += os.read(self.fd, 100)
                except BlockingIOError:
                    pass
        return got


def monitor_status(ros):
    rec = ros.probe({"listen": [{"topic": "/diagnostics", "type": "diagnostic_msgs/DiagnosticArray"}],
                     "steps": [{"sleep": 2.5}]})
    return [s for r in rec if r["kind"] == "recv" for s in r["msg"]["status"] if s["name"] == "rubass: monitor"][-1]


def test_a_board_unplugged_while_its_stop_is_active_gets_the_stop_again_when_it_returns(ros, tmp_path):
    if not shutil.which("socat"):
        pytest.skip("socat is missing (tools/deps.sh installs it)")
    board = Socat(tmp_path)
    board.start()
    try:
        lib = LIB + (f'  board_stop: {{plugin: serial, port: {board.board}, baud: 115200, on_start: "S\\n", '
                     f'on_release: "R\\n"}}\n')
        path = spec(tmp_path, "action primitive board_stop;\nentity a { rules: r: topic /x.data > 1; }\n"
                              "if (a.r) then { board_stop; }\n", lib=lib)
        mon = ros.monitor(path)
        x = lambda v: {"publish": "/x", "msg": {"data": v}}  # noqa: E731
        ros.probe({"advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
                   "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.2}, x(5.0), {"sleep": 0.3}]})
        assert board.read(1.0, b"S\n") == b"S\n", ros.log(mon)
        board.stop()  # unplugged, while the behaviour is still active
        time.sleep(1.0)  # two reopen periods
        away = monitor_status(ros)
        assert away["level"] in (2, b"\x02"), (away, ros.log(mon))
        board.start()  # back, power-cycled: it knows nothing
        assert board.read(3.0, b"S\n") == b"S\n", ros.log(mon)  # once, not S\nS\n, not nothing
        wait_log(mon, ros, "is back: start written again")
        status = monitor_status(ros)
        assert status["level"] in (0, b"\x00"), status
        ros.probe({"advertise": [{"topic": "/x", "type": "std_msgs/Float64"}],
                   "steps": [{"wait_subscribers": "/x"}, {"sleep": 0.2}, x(0.0), {"sleep": 0.3}]})
        assert board.read(1.0, b"R\n") == b"R\n", ros.log(mon)
    finally:
        board.stop()
