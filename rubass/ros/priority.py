"""The monitor's scheduling priority (~nice). On a robot computer that is busy, the monitor's
threads wait behind the robot's own for a core: with two CPU-bound processes on this 2-core VM,
a `for` stop was dispatched up to 5.3 ms after it became due; at nice -10, at most 2.0 ms
(`rubass experiments`, docs/monitor.md). Linux gives each thread its own nice value and a new
thread its creator's, so every thread alive is set, and those started later inherit it."""
from __future__ import annotations

import os
from typing import Optional


def set_nice(nice: int) -> Optional[str]:
    """Give every thread of this process the nice value `nice`; None, or why it could not."""
    try:
        tids = [int(t) for t in os.listdir("/proc/self/task")]
    except OSError:  # no /proc (not Linux): the process's own value
        tids = [0]
    before = os.getpriority(os.PRIO_PROCESS, 0)
    for tid in tids:
        try:
            os.setpriority(os.PRIO_PROCESS, tid, nice)
        except ProcessLookupError:  # a thread that ended meanwhile
            continue
        except PermissionError:
            for done in tids[:tids.index(tid)]:  # all threads alike: back to where they were
                try:
                    os.setpriority(os.PRIO_PROCESS, done, before)
                except OSError:
                    pass
            return (f"~nice {nice}: not permitted (a nice value below the current {before} needs root, "
                    f"CAP_SYS_NICE or a 'nice' limit in /etc/security/limits.conf); running at nice {before}")
        except OSError as exc:
            return f"~nice {nice}: {exc.strerror or exc}; running at nice {before}"
    return None
