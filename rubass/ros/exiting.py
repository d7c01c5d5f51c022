"""Exit even when rospy cannot shut down: its shutdown waits for a subscription that retries a
master which is down (the registration holds its topic manager's lock), and so did the process."""
from __future__ import annotations

import os
import sys
import threading
import time

EXIT_GRACE = 5.0  # s: rospy's own shutdown, after the monitor's, before the process exits anyway


def exit_within(seconds: float, code: int = 0, done: str = "the monitor had already stopped",
                what: str = "rospy did not shut down") -> None:
    """Exit with `code` after `seconds` whatever is still running: rospy's shutdown waits for a subscription
    that retries a master which is down (its topic manager's lock), and so did the process, for good.
    `done`: what had been done before, and `what` did not happen in time, for the line that says so."""
    def cut() -> None:
        time.sleep(seconds)
        sys.stderr.write(f"[rubass] {what} within {seconds:g} s (a registration waits for the master): "
                         f"exiting; {done}\n")
        sys.stderr.flush()
        sys.stdout.flush()
        os._exit(code)

    threading.Thread(target=cut, name="rubass-exit", daemon=True).start()
