"""The monitor's scheduling priority (~nice). On a robot computer that is busy, the monitor's
threads wait behind the robot's own for a core: with two CPU-bound processes on this 2-core VM,
a `for` stop was dispatched up to 5.3 ms after it became due; at nice -10, at most 2.0 ms
(`rubass experiments`, docs/monitor.md). Linux gives each thread its own nice value and a new
thread its creator's, so every thread alive is set, and those started later inherit it."""
from __future__ import annotations

import os
from typing import Dict, List, Optional


def _threads() -> List[int]:
    """This process's thread ids; [0] (the process itself, to os.getpriority) where /proc is missing."""
    try:
        return [int(t) for t in os.listdir("/proc/self/task")]
    except OSError:  # not Linux
        return [0]


def set_nice(nice: int) -> Optional[str]:
    """Give every thread of this process the nice value `nice`; None, or why it could not."""
    tids = _threads()
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


def thread_nice_values() -> Dict[int, int]:
    """Nice value -> how many of this process's threads run at it (one value unless changed from outside)."""
    out: Dict[int, int] = {}
    for tid in _threads():
        try:
            value = os.getpriority(os.PRIO_PROCESS, tid)  # Linux: a thread id names that thread alone
        except OSError:  # a thread that ended meanwhile
            continue
        out[value] = out.get(value, 0) + 1
    return out or {os.getpriority(os.PRIO_PROCESS, 0): 1}


def describe(values: Dict[int, int], asked: Optional[int], refused: bool) -> str:
    """The `nice` of /diagnostics: the threads' value, or each value with its number of threads (a renice
    from outside changes one thread only), and whether ~nice was refused."""
    text = str(next(iter(values))) if len(values) == 1 else "mixed: " + ", ".join(
        f"{v} ({n} thread{'s' * (n != 1)})" for v, n in sorted(values.items()))
    return f"{text} (~nice {asked} was not permitted)" if refused and asked is not None else text
