"""A FATAL message (the monitor cannot start) is printed once, not twice."""
import os
import subprocess

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
    proc = subprocess.run([PY, os.path.join(ROOT, "scripts", "agent"), "__name:=agent", "_node_rate:=0"],
                          env=ros.env, capture_output=True, text=True, timeout=60, cwd=str(tmp_path))
    assert proc.returncode == 1
    out = proc.stdout + proc.stderr
    assert out.count("rubass agent: cannot start") == 1, out
