"""The engine thread's timer slack (rubass/ros/timerslack.py): 1 ns for the calling thread only."""
import ctypes
import sys
import threading

import pytest

from rubass.ros.timerslack import exact_timers

PR_GET_TIMERSLACK = 30


def slack():
    return ctypes.CDLL(None, use_errno=True).prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux only")
def test_the_calling_thread_gets_exact_timers_and_the_others_keep_theirs():
    seen = {}

    def engine():
        seen["before"] = slack()
        seen["ok"] = exact_timers()
        seen["after"] = slack()

    before = slack()
    t = threading.Thread(target=engine)
    t.start()
    t.join()
    assert seen == {"before": before, "ok": True, "after": 1}
    assert slack() == before > 1, "the other threads keep theirs"
