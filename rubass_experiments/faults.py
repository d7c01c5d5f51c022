"""The faults of the paper's experiments, as models a simulated robot applies."""
from __future__ import annotations

import math
import random
from dataclasses import dataclass
from typing import Optional


# Chance per encoder reading (20 Hz) of a burst of noise from a half-broken quadrature line.
# Calibrated so that a monitor with no delay of its own reacts to the paper's E rows in about
# the paper's average time (the paper does not describe its noise): each burst restarts the
# rule's `for 0.4 s`, so this rate, not the monitor, sets those rows' reaction times.
NOISE_RATE = 0.02


@dataclass
class WheelFault:
    """Hardware faults of one wheel of the Frobit-like base (paper §4.1)."""

    encoder_dead: bool = False    # E_x: one line of the quadrature encoder cut
    motor_full: bool = False      # M_x: H-bridge forced to full speed, direction still controlled
    full_speed: float = 1.0       # m/s
    deadband: float = 0.05        # m/s: smaller commands leave the direction pin as it was
    direction: float = 1.0

    def motor_target(self, commanded: float) -> float:
        if self.motor_full:
            # like a motor driver's direction pin: it follows the command's sign, but a command
            # inside the deadband (the controller hovering around zero) does not flip it
            if abs(commanded) > self.deadband:
                self.direction = math.copysign(1.0, commanded)
            return self.direction * self.full_speed
        return commanded

    def encoder_reading(self, actual: float, rng: random.Random) -> float:
        """What the encoder reports. A half-broken quadrature line reads 0, with now and then
        a burst of noise from the line that still works (the paper's E rows)."""
        if not self.encoder_dead:
            return actual + rng.gauss(0.0, 0.002)
        if rng.random() < NOISE_RATE:
            return rng.choice((-1.0, 1.0)) * rng.uniform(0.03, 0.08)
        return 0.0


@dataclass
class Drift:
    """An increasing drift added to a velocity command after a start time (paper §4.2 (2))."""

    rate: float                   # added per second (m/s² or rad/s²)
    start: Optional[float] = None

    def amount(self, now: float) -> float:
        return 0.0 if self.start is None or now < self.start else self.rate * (now - self.start)
