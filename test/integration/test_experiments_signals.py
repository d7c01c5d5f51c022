"""`rubass experiments` stopped by a signal (issue 19): every process it started is gone a few
seconds later, the interrupted run's bag is closed, the finished runs are tabled as interrupted,
and the exit status is 128 + the signal. SIGKILL of the runner too: its children notice.

Processes are found by a unique marker in their environment (inherited from the command),
never by name: other tests and engineers run ROS processes on the same machine."""
import ctypes
import json
import os
import signal
import subprocess
import sys
import time
import uuid

import pytest

from conftest import ROOT

pytestmark = [pytest.mark.ros, pytest.mark.slow]

ROW, RUN_DIR = "Spin (0 s)", "Spin_0_s"  # the shortest row
TEST_MARK = "RUBASS_SIGNALS_TEST"
_prctl = ctypes.CDLL(None, use_errno=True).prctl


def _ours(mark):
    """pid -> command line of every live (not zombie) process with the marker."""
    tag = f"{TEST_MARK}={mark}".encode()
    found = {}
    for name in os.listdir("/proc"):
        if not name.isdigit():
            continue
        try:
            with open(f"/proc/{name}/stat", "rb") as fh:
                stat = fh.read()
            if stat[stat.rindex(b")") + 2:].split()[0] == b"Z":
                continue
            with open(f"/proc/{name}/environ", "rb") as fh:
                if tag not in fh.read().split(b"\0"):
                    continue
            with open(f"/proc/{name}/cmdline", "rb") as fh:
                found[int(name)] = fh.read().replace(b"\0", b" ").decode(errors="replace")[:120]
        except (OSError, ValueError, IndexError):
            continue
    return found


def _child_setup():
    # default dispositions whatever the test runner ignores (a background job ignores SIGINT, nohup SIGHUP),
    # and the command dies with this test process
    for sig in (signal.SIGINT, signal.SIGHUP, signal.SIGTERM):
        signal.signal(sig, signal.SIG_DFL)
    _prctl(1, int(signal.SIGKILL), 0, 0, 0)


class Experiments:
    """`rubass experiments` on one short row, in the background, with a marker in its environment."""

    def __init__(self, tmp_path, reps):
        if not os.path.exists("/usr/bin/rosmaster"):
            pytest.skip("ROS 1 is not installed")
        self.mark = uuid.uuid4().hex
        self.out = tmp_path / "out"
        self.stdout, self.stderr = tmp_path / "stdout", tmp_path / "stderr"
        env = dict(os.environ, PYTHONUNBUFFERED="1", **{TEST_MARK: self.mark})
        with open(self.stdout, "w") as out, open(self.stderr, "w") as err:
            self.proc = subprocess.Popen([sys.executable, "-m", "rubass", "experiments", "--reps", str(reps),
                                          "--only", ROW, "--out", str(self.out)], cwd=ROOT, env=env, stdout=out,
                                         stderr=err, stdin=subprocess.DEVNULL, start_new_session=True,
                                         preexec_fn=_child_setup)

    def text(self):
        return self.stdout.read_text() + "\n--- stderr ---\n" + self.stderr.read_text()

    def bag(self, rep):
        return self.out / "runs" / RUN_DIR / str(rep) / "run.bag"

    def wait_recording(self, rep, timeout=120.0):
        """Until run `rep` is recording and its monitor enforces the spec (its nodes have been up
        for a while: the bag holds messages), then half a second more: the run still has its
        warm-up (1.5 s) before the fault."""
        active = str(self.bag(rep)) + ".active"
        monitor_log = self.bag(rep).parent / "monitor.log"
        end = time.time() + timeout
        while not (os.path.exists(active) and monitor_log.exists() and "rubass: enforcing" in monitor_log.read_text()):
            assert self.proc.poll() is None, f"exited {self.proc.returncode} before run {rep} was up\n{self.text()}"
            assert time.time() < end, f"run {rep} never came up\n{self.text()}"
            time.sleep(0.1)
        time.sleep(0.5)
        assert os.path.exists(active), f"run {rep} ended before the signal could interrupt it\n{self.text()}"

    def wait_gone(self, timeout):
        """The marked processes still alive after `timeout` seconds (none, when all is well)."""
        end = time.time() + timeout
        left = _ours(self.mark)
        while left and time.time() < end:
            time.sleep(0.2)
            left = _ours(self.mark)
        return left

    def kill_all(self):
        for pid in _ours(self.mark):
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait(10)


@pytest.fixture
def experiments(tmp_path):
    started = []

    def start(reps=2):
        e = Experiments(tmp_path, reps)
        started.append(e)
        return e

    yield start
    for e in started:  # every exit path: nothing of ours outlives the test
        e.kill_all()


def _signal_mid_run(e, sig):
    left = _ours(e.mark)
    # the command, its reaper, the master, the base, the injector, the driver, the recorder (the monitor)
    assert len(left) >= 6, left
    os.kill(e.proc.pid, sig)
    try:
        status = e.proc.wait(60)
    except subprocess.TimeoutExpired:
        pytest.fail(f"still running 60 s after {sig.name}\n{e.text()}")
    return status


def _assert_bag_closed(bag):
    import rosbag

    assert bag.exists() and not os.path.exists(str(bag) + ".active"), os.listdir(bag.parent)
    with rosbag.Bag(str(bag)) as b:  # opens without reindexing: its index was written
        assert b.get_message_count() > 0


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGHUP], ids=["SIGINT", "SIGHUP"])
def test_a_stop_signal_stops_every_process_and_closes_the_bag(experiments, sig):
    e = experiments()
    e.wait_recording(0)
    status = _signal_mid_run(e, sig)
    assert status == 128 + sig, e.text()
    left = e.wait_gone(5.0)
    assert not left, f"left running after {sig.name}: {left}"
    _assert_bag_closed(e.bag(0))
    assert f"interrupted by {sig.name}" in e.text()
    assert "Traceback" not in e.text(), e.text()


def test_sigterm_after_a_finished_run_tables_it_as_interrupted(experiments):
    e = experiments()
    e.wait_recording(1)  # run 0 has finished
    status = _signal_mid_run(e, signal.SIGTERM)
    assert status == 143, e.text()
    left = e.wait_gone(5.0)
    assert not left, f"left running after SIGTERM: {left}"
    _assert_bag_closed(e.bag(1))
    _assert_bag_closed(e.bag(0))
    out = e.stdout.read_text()
    assert "INTERRUPTED by SIGTERM" in out, e.text()
    row = next(line for line in out.splitlines() if line.startswith(ROW))
    assert row.endswith("(interrupted)") and "| 1/1" in row, row
    data = json.loads((e.out / "table.json").read_text())
    assert data["interrupted"]["signal"] == "SIGTERM" and data["interrupted"]["finished_runs"] == 1
    assert data["interrupted"]["cut_short"]["rep"] == 1
    assert [(r["row"], r["runs"], r["interrupted"]) for r in data["rows"]] == [(ROW, 1, True)]
    assert "Traceback" not in e.text(), e.text()


def test_children_die_when_the_runner_is_sigkilled(experiments):
    e = experiments()
    e.wait_recording(0)
    runner = e.proc.pid
    _signal_mid_run(e, signal.SIGKILL)
    # the kernel signals the children (PDEATHSIG) at once; the reaper SIGKILLs a straggler after 5 s
    left = e.wait_gone(12.0)
    assert not left, f"left running after the runner was SIGKILLed: {left}"
    assert runner not in left
    _assert_bag_closed(e.bag(0))  # the recorder got SIGINT, not SIGKILL


def test_a_ctrl_c_that_lands_inside_the_master_check_stops_the_command(tmp_path):
    """rosgraph's is_master_online swallows every exception with a bare `except`: a Ctrl-C that landed
    inside it while a row's master started raised Interrupted there and was lost (the Supervisor raises
    once; a second Ctrl-C is ignored while stopping), so the experiments went on. Here the signal is
    raised from inside the first master check; the runner's PrivateMaster must raise Interrupted and
    leave no master running (the one it had started was left running when its start was cut short)."""
    code = ("import os, signal, sys\n"
            "from rubass_experiments.master import PrivateMaster\nfrom rubass_experiments.procs import Interrupted, Supervisor\n"
            "import subprocess\nstarted = []\nPopen = subprocess.Popen\n"
            "def popen(*a, **k):\n    started.append(Popen(*a, **k))\n    return started[-1]\n"
            "subprocess.Popen = popen\n"
            "import rubass.ros.rpc as rpc\nreal = rpc.Caller.call\nsent = []\n"
            "def call(self, *a):\n    if not sent:\n        sent.append(1)\n        os.kill(os.getpid(), signal.SIGINT)\n"
            "    return real(self, *a)\n"
            "rpc.Caller.call = call\n"
            "try:\n    with Supervisor():\n        m = PrivateMaster(sys.argv[1])\n"
            "        print('started', m.process.pid, flush=True)\n        m.stop()\n"
            "except Interrupted:\n    print('interrupted', flush=True)\n"
            "print('left running:', [p.args for p in started if p.poll() is None], flush=True)\n")
    out = subprocess.run([sys.executable, "-c", code, str(tmp_path / "home")], cwd=ROOT, capture_output=True,
                         text=True, timeout=60)
    assert out.stdout == "interrupted\nleft running: []\n", (out.stdout, out.stderr)
    assert "Traceback" not in out.stderr, out.stderr

