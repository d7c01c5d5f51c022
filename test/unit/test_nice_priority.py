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
        tids = os.listdir("/proc/self/task")
        values = {int(open(f"/proc/self/task/{t}/stat").read().rsplit(")", 1)[1].split()[16]) for t in tids}
        stop.set()  # after the count: the threads then end
        print(sorted(values), len(tids))
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


def test_diagnostics_name_each_value_when_a_renice_changed_one_thread_and_a_refusal_only_when_refused():
    """An acceptance sweep: `renice -p PID` changes the main thread only, and /diagnostics said -10 for
    a monitor whose other 11 threads ran at 0; a ~nice granted, then changed from outside, read as refused."""
    assert priority.describe({-10: 12}, -10, False) == "-10"
    assert priority.describe({-10: 1, 0: 11}, None, False) == "mixed: -10 (1 thread), 0 (11 threads)"
    assert priority.describe({0: 12}, -6, False) == "0"  # granted, then reniced from outside: not "refused"
    assert priority.describe({0: 12}, -5, True) == "0 (~nice -5 was not permitted)"


def test_the_threads_values_are_read_from_each_thread():
    values = priority.thread_nice_values()
    assert sum(values.values()) == len(os.listdir("/proc/self/task"))
    assert os.getpriority(os.PRIO_PROCESS, 0) in values


def test_null_private_parameters_are_named():
    from rubass.ros.startup import null_params

    argv = ["monitor", "_spec:=s.rbs", "_nice:=null", "_rate:=~", "__name:=x", "_x:=", "_q:=[", "y:=null"]
    assert null_params(argv) == ["nice", "rate", "x"]
