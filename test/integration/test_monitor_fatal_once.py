"""A FATAL message (the monitor cannot start) is printed once, not twice."""
import os
import signal
import subprocess
import time

import pytest

from conftest import ROOT
from rosharness import PY

pytestmark = pytest.mark.ros


def test_a_fatal_message_is_printed_once(ros, tmp_path):
    proc = subprocess.run([PY, os.path.join(ROOT, "scripts", "monitor"), "__name:=rubass"], env=ros.env,
                          capture_output=True, text=True, timeout=60, cwd=str(tmp_path))
    assert proc.returncode == 1
    out = proc.stdout + proc.stderr
    assert out.count("~spec is required") == 1, out
    assert out.count("cannot start") == 1, out


def test_the_agents_fatal_message_is_printed_once(ros, tmp_path):
    """The agent stays up with a bad parameter (no respawn loop under agent.launch, docs/multihost.md),
    says so once, and exits 1 when stopped."""
    proc = subprocess.Popen([PY, os.path.join(ROOT, "scripts", "agent"), "__name:=agent", "_node_rate:=0"],
                            env=ros.env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            cwd=str(tmp_path), start_new_session=True)
    try:
        time.sleep(4.0)  # up, and said why it reports nothing
        assert proc.poll() is None, proc.communicate()[0]
        proc.send_signal(signal.SIGTERM)
        out, _ = proc.communicate(timeout=20)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert proc.returncode == 1, out
    assert out.count("rubass agent: cannot start") == 1, out
