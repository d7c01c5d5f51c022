"""Exit even when rospy cannot shut down: its shutdown waits for a subscription that retries a
master which is down (the registration holds its topic manager's lock), and so did the process."""
from __future__ import annotations

import os
import sys
import threading
import time

EXIT_GRACE = 5.0  # s: rospy's own shutdown, after the monitor's, before the process exits anyway


def exit_within(seconds: float) -> None:
    """Exit 0 after `seconds` whatever is still running: rospy's shutdown waits for a subscription
    that retries a master which is down (its topic manager's lock), and so did the process, for good."""
    def cut() -> None:
        time.sleep(seconds)
        sys.stderr.write(f"[rubass] rospy did not shut down within {seconds:g} s (a registration waits for the "
                         f"master): exiting; the monitor had already stopped\n")
        sys.stderr.flush()
        sys.stdout.flush()
        os._exit(0)

    threading.Thread(target=cut, name="rubass-exit", daemon=True).start()
