"""~nice: every thread of the monitor gets the nice value (Linux keeps one per thread), and a
refusal is a message and a rollback, never an exception that would keep the monitor from starting."""
import os
import subprocess
import sys

import pytest

from rubass.ros import priority
from conftest import ROOT

pytestmark = pytest.mark.skipif(not os.path.isdir("/proc/self/task"), reason="Linux only")


def test_every_thread_alive_and_every_later_one_gets_the_value():
    code = """if True:
        import os, threading, time
        from rubass.ros.priority import set_nice
        stop = threading.Event()
        early = threading.Thread(target=stop.wait); early.start()
        assert set_nice(os.getpriority(os.PRIO_PROCESS, 0) + 3) is None
        late = threading.Thread(target=stop.wait); late.start()
        values = {int(open(f"/proc/self/task/{t}/stat").read().rsplit(")", 1)[1].split()[16])
                  for t in os.listdir("/proc/self/task")}
        stop.set()
        print(sorted(values), len(os.listdir("/proc/self/task")))
    """
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=30)
    assert out.returncode == 0, out.stderr
    values, threads = out.stdout.split("] ")
    assert int(threads) == 3
    assert values.strip("[") == str(os.getpriority(os.PRIO_PROCESS, 0) + 3)


def test_a_refusal_is_a_message_and_the_threads_set_so_far_go_back(monkeypatch):
    calls = []
    monkeypatch.setattr(priority.os, "listdir", lambda path: ["11", "12", "13"])
    monkeypatch.setattr(priority.os, "getpriority", lambda which, who: 0)

    def setpriority(which, tid, value):
        calls.append((tid, value))
        if tid == 12 and value == -10:
            raise PermissionError(1, "Operation not permitted")

    monkeypatch.setattr(priority.os, "setpriority", setpriority)
    message = priority.set_nice(-10)
    assert message.startswith("~nice -10: not permitted") and message.endswith("running at nice 0")
    assert "CAP_SYS_NICE" in message and "limits.conf" in message
    assert calls == [(11, -10), (12, -10), (11, 0)]  # thread 13 never changed, thread 11 put back


def test_a_thread_that_ended_meanwhile_is_skipped(monkeypatch):
    monkeypatch.setattr(priority.os, "listdir", lambda path: ["11", "12"])
    monkeypatch.setattr(priority.os, "getpriority", lambda which, who: 0)
    done = []

    def setpriority(which, tid, value):
        if tid == 11:
            raise ProcessLookupError(3, "No such process")
        done.append(tid)

    monkeypatch.setattr(priority.os, "setpriority", setpriority)
    assert priority.set_nice(5) is None and done == [12]
