"""A differential-drive base: wheel speeds with a first-order lag, integrated pose."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Tuple


@dataclass
class DiffDrive:
    track: float = 0.23          # wheel separation (m)
    lag: float = 0.08            # wheel speed time constant (s): a real wheel cannot reverse at once
    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0
    left: float = 0.0            # actual wheel speeds (m/s)
    right: float = 0.0

    def wheels_for(self, v: float, w: float) -> Tuple[float, float]:
        """Wheel speeds that give body speed v (m/s) and turn rate w (rad/s)."""
        return v - w * self.track / 2.0, v + w * self.track / 2.0

    def body(self) -> Tuple[float, float]:
        """Body speed and turn rate from the actual wheel speeds."""
        return (self.left + self.right) / 2.0, (self.right - self.left) / self.track

    def step(self, left_target: float, right_target: float, dt: float) -> None:
        """Move the wheels toward their targets and integrate the pose over dt."""
        a = 1.0 - math.exp(-dt / self.lag) if self.lag > 0 else 1.0
        self.left += (left_target - self.left) * a
        self.right += (right_target - self.right) * a
        v, w = self.body()
        self.x += v * math.cos(self.yaw + w * dt / 2.0) * dt
        self.y += v * math.sin(self.yaw + w * dt / 2.0) * dt
        self.yaw = math.atan2(math.sin(self.yaw + w * dt), math.cos(self.yaw + w * dt))


def go_to_goal(x: float, y: float, yaw: float, gx: float, gy: float, v_max: float, w_max: float) -> Tuple[float, float]:
    """A proportional go-to-goal law: (v, w) toward the goal, slowing when misaligned or close."""
    dx, dy = gx - x, gy - y
    dist = math.hypot(dx, dy)
    if dist < 0.05:
        return 0.0, 0.0
    err = math.atan2(math.sin(math.atan2(dy, dx) - yaw), math.cos(math.atan2(dy, dx) - yaw))
    w = max(-w_max, min(w_max, 2.0 * err))
    v = max(0.0, min(v_max, 0.8 * dist)) * max(0.0, math.cos(err))
    return v, w
