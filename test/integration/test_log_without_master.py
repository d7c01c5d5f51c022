"""rospy's log calls ask the master for /rosout_disable_topics_generation each time it is unset
(found with a cut-off master host in a network-namespace test): a log call then blocks until the
master answers. keep_rosout_flag() answers it once; a stopped (SIGSTOP) master, which accepts
connections and never answers, stands in for the cut-off host."""
import os
import signal
import subprocess
import sys

import pytest

from conftest import ROOT

pytestmark = pytest.mark.ros

NODE = r'''
import os, signal, sys, threading, time
sys.path.insert(0, sys.argv[2])
import rospy
from rubass.ros.rosout_param import keep_rosout_flag
rospy.init_node("logger", disable_signals=True)
rospy.loginfo("up")
if sys.argv[1] == "keep":
    assert keep_rosout_flag()
os.kill(int(os.environ["MASTER_PID"]), signal.SIGSTOP)
try:
    done = threading.Event()
    threading.Thread(target=lambda: (rospy.logwarn("while the master is away"), done.set()), daemon=True).start()
    print("returned" if done.wait(3.0) else "blocked", flush=True)
finally:
    os.kill(int(os.environ["MASTER_PID"]), signal.SIGCONT)
os._exit(0)
'''


@pytest.mark.parametrize("mode,expected", [("keep", "returned"), ("plain", "blocked")])
def test_a_log_call_does_not_wait_for_the_master(ros, tmp_path, mode, expected):
    script = tmp_path / "node.py"
    script.write_text(NODE)
    env = dict(ros.env, MASTER_PID=str(ros.master.process.pid))
    out = subprocess.run([sys.executable, str(script), mode, ROOT], env=env, capture_output=True, text=True,
                         timeout=60)
    os.kill(ros.master.process.pid, signal.SIGCONT)  # whatever happened
    assert out.stdout.strip().splitlines()[-1:] == [expected], out.stdout + out.stderr
