"""A Frobit-like simulated base (node /frobit_base) with its safety board.

Wheels: commands on /wheel_left/cmd and /wheel_right/cmd (std_msgs/Float64, m/s) and, with
priority for 0.5 s after each message, on /wheel_X/safety_cmd; measured speeds on
/wheel_left/encoder and /wheel_right/encoder (Float64, m/s, 20 Hz); /odom from the actual
wheel speeds. Hardware faults (JSON on /sim/fault: {"wheels": {"left": {"encoder_dead": true,
"motor_full": true}, "right": {}}}) act as in the paper: a half-broken quadrature line reads
0 with bursts of noise; a forced H-bridge runs the motor at full speed in the commanded
direction, and no software command can slow it.

The safety board, as the paper's Arduino-type board: a serial line (a pseudo-terminal; its
name is linked at ~board_port) on which "S\\n" cuts the motors and "R\\n" re-enables them;
and a watchdog that cuts them when the monitor's heartbeat (~heartbeat_topic) has been
silent for ~watchdog seconds, once it has been seen.
"""
from __future__ import annotations

import os
import random
import select
import threading
import time
import tty
from typing import Dict

import rospy
from std_msgs.msg import Float64, Header

from .faults import WheelFault
from .kinematics import DiffDrive
from .common import as_hardware, loop, odometry, on_fault
from .eventlog import EventLog

MUX_TIMEOUT = 0.5
SIDES = ("left", "right")


class SafetyBoard:
    """Cuts the motors on 'S', re-enables on 'R'; cuts them when the heartbeat stops."""

    def __init__(self, link: str, watchdog: float, log: EventLog) -> None:
        self.cut = False
        self.log = log
        self.watchdog = watchdog
        self.last_beat = None  # type: ignore[assignment]
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        self.port = os.ttyname(self.slave)
        if link:
            if os.path.lexists(link):
                os.unlink(link)
            os.symlink(self.port, link)
        threading.Thread(target=self._read, name="board-serial", daemon=True).start()

    def _read(self) -> None:
        buf = b""
        while True:
            if not select.select([self.master], [], [], 0.5)[0]:
                continue
            try:
                buf += os.read(self.master, 64)
            except OSError:
                time.sleep(0.05)
                continue
            while b"\n" in buf:
                line, buf = buf.split(b"\n", 1)
                if line.strip() == b"S":
                    self.cut = True
                    self.log.log("stop_received", once=True, source="board")
                elif line.strip() == b"R":
                    self.cut = False
                    self.log.log("board_reenabled")

    def beat(self, _: Header) -> None:
        self.last_beat = time.monotonic()

    def check_watchdog(self) -> None:
        if self.last_beat is not None and not self.cut and time.monotonic() - self.last_beat > self.watchdog:
            self.cut = True
            self.log.log("watchdog_cut", once=True, silent_for=time.monotonic() - self.last_beat)


def main() -> None:
    as_hardware()
    rospy.init_node("frobit_base")
    log = EventLog(rospy.get_param("~events_file", None))
    board = SafetyBoard(rospy.get_param("~board_port", ""), float(rospy.get_param("~watchdog", 0.25)), log)
    rng = random.Random(rospy.get_param("~seed", None))
    base = DiffDrive(track=0.3, lag=0.1)
    faults: Dict[str, WheelFault] = {s: WheelFault() for s in SIDES}
    cmd = {s: (0.0, 0.0) for s in SIDES}
    safety = {s: (0.0, -1e9) for s in SIDES}

    def fault(f: Dict) -> None:
        wheels = f.get("wheels")
        if wheels:
            for side in SIDES:
                faults[side] = WheelFault(**wheels.get(side, {}))
            log.log("fault_applied", fault=wheels)

    on_fault(fault)
    for side in SIDES:
        rospy.Subscriber(f"/wheel_{side}/cmd", Float64,
                         lambda m, s=side: cmd.__setitem__(s, (m.data, time.monotonic())), tcp_nodelay=True)
        rospy.Subscriber(f"/wheel_{side}/safety_cmd", Float64,
                         lambda m, s=side: safety.__setitem__(s, (m.data, time.monotonic())), tcp_nodelay=True)
    rospy.Subscriber(rospy.get_param("~heartbeat_topic", "/rubass/heartbeat"), Header, board.beat, tcp_nodelay=True)
    enc = {s: rospy.Publisher(f"/wheel_{s}/encoder", Float64, queue_size=10, tcp_nodelay=True) for s in SIDES}
    odom = rospy.Publisher("/odom", type(odometry(base, rospy.Time())), queue_size=10, tcp_nodelay=True)
    dt, ticks = 0.01, [0]

    def step() -> None:
        now = time.monotonic()
        board.check_watchdog()
        targets = []
        for side in SIDES:
            value, at = safety[side] if now - safety[side][1] < MUX_TIMEOUT else cmd[side]
            if now - at >= MUX_TIMEOUT:
                value = 0.0
            targets.append(0.0 if board.cut else faults[side].motor_target(value))
        base.step(targets[0], targets[1], dt)
        ticks[0] += 1
        if ticks[0] % 5 == 0:  # encoders and odometry at 20 Hz
            for side, actual in zip(SIDES, (base.left, base.right)):
                enc[side].publish(Float64(faults[side].encoder_reading(actual, rng)))
            odom.publish(odometry(base, rospy.Time.now()))

    loop(1.0 / dt, step)


if __name__ == "__main__":
    main()
