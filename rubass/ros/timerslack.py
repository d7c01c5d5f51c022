"""Exact wake-ups for the engine's thread. Linux lets the timer of a sleeping thread fire up to
its "timer slack" late (50 µs by default), to merge wake-ups and save power; a `for` deadline
wants none of that lateness. Linux only: elsewhere the default slack stays."""
from __future__ import annotations

import ctypes

PR_SET_TIMERSLACK = 29  # <linux/prctl.h>


def exact_timers() -> bool:
    """Set the calling thread's timer slack to 1 ns; False where it cannot be set."""
    try:
        return int(ctypes.CDLL(None, use_errno=True).prctl(PR_SET_TIMERSLACK, 1, 0, 0, 0)) == 0
    except (OSError, AttributeError):  # no C library, or no prctl (not Linux)
        return False
