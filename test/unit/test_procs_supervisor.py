"""The process Supervisor (rubass_experiments/procs.py) with plain `sleep` children, no ROS: stop
signals become one Interrupted, children die with a SIGKILLed parent (PDEATHSIG for the ones
it spawned, the reaper for one started otherwise), a clean exit stops everything."""
import os
import signal
import subprocess
import sys
import textwrap
import time
import uuid

import pytest

from conftest import ROOT
from rubass_experiments.procs import Interrupted, Supervisor

MARK = "RUBASS_PROCS_TEST"


def _alive(pid):
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            stat = fh.read()
    except OSError:
        return False
    return stat[stat.rindex(b")") + 2:].split()[0] != b"Z"


def _wait_dead(pids, timeout):
    end = time.time() + timeout
    while any(_alive(p) for p in pids) and time.time() < end:
        time.sleep(0.05)
    return [p for p in pids if _alive(p)]


def _run_child(body, mark):
    """A python child running `body` with a Supervisor `sup`; it prints its children's pids."""
    code = textwrap.dedent("""
        import os, subprocess, sys, time
        sys.path.insert(0, %r)
        from rubass_experiments.procs import Supervisor, Interrupted
        sup = Supervisor()
        with sup:
        %s
    """) % (ROOT, textwrap.indent(textwrap.dedent(body), "    "))
    env = dict(os.environ, **{MARK: mark})
    return subprocess.Popen([sys.executable, "-c", code], env=env, stdout=subprocess.PIPE, text=True,
                            start_new_session=True)


def _kill_marked(mark):
    tag = f"{MARK}={mark}".encode()
    for name in os.listdir("/proc"):
        if name.isdigit():
            try:
                with open(f"/proc/{name}/environ", "rb") as fh:
                    if tag in fh.read().split(b"\0"):
                        os.kill(int(name), signal.SIGKILL)
            except OSError:
                pass


@pytest.fixture
def mark():
    m = uuid.uuid4().hex
    yield m
    _kill_marked(m)


def test_children_die_with_a_sigkilled_parent(mark):
    child = _run_child("""
        a = sup.spawn(["sleep", "60"])                       # PDEATHSIG
        b = subprocess.Popen(["sleep", "60"], start_new_session=True)  # only the marker: the reaper
        print(a.pid, b.pid, flush=True)
        time.sleep(60)
    """, mark)
    pids = [int(p) for p in child.stdout.readline().split()]
    assert len(pids) == 2 and all(_alive(p) for p in pids)
    child.kill()
    child.wait(10)
    assert _wait_dead(pids[:1], 2.0) == []        # the kernel, at once
    assert _wait_dead(pids[1:], 8.0) == []        # the reaper: SIGTERM at once, SIGKILL after 5 s


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP, signal.SIGINT], ids=["TERM", "HUP", "INT"])
def test_a_stop_signal_raises_interrupted_once_and_everything_is_stopped(mark, sig):
    child = _run_child("""
        a = sup.spawn(["sleep", "60"])
        try:
            print(a.pid, flush=True)
            time.sleep(60)
        except Interrupted as exc:
            os.kill(os.getpid(), exc.signum)  # a second signal during the cleanup: noted, not raised
            time.sleep(0.2)
            print("interrupted", exc.name, exc.exit_status, flush=True)
            sys.exit(exc.exit_status)
    """, mark)
    pid = int(child.stdout.readline())
    os.kill(child.pid, sig)
    assert child.stdout.readline().split() == ["interrupted", sig.name, str(128 + sig)]
    assert child.wait(10) == 128 + sig
    assert _wait_dead([pid], 2.0) == []


def test_a_signal_while_deferred_is_raised_on_leaving():
    sup = Supervisor()
    with sup:
        assert signal.getsignal(signal.SIGTERM) == sup._on_signal  # or the SIGTERM below would end pytest
        with pytest.raises(Interrupted) as exc:
            with sup.deferred():
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(0.05)  # the handler ran here, and did not raise
                reached = True
        assert reached and exc.value.exit_status == 143
        sup.check()  # raised once only
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL


def test_an_inherited_ignore_is_kept(mark):
    child = _run_child("""
        import signal
        print(signal.getsignal(signal.SIGHUP) is signal.SIG_IGN, flush=True)
    """, mark)
    assert child.stdout.readline().strip() == "False"
    out = subprocess.run([sys.executable, "-c", f"import sys; sys.path.insert(0, {ROOT!r})\n"
                          "import signal\nsignal.signal(signal.SIGHUP, signal.SIG_IGN)\n"
                          "from rubass_experiments.procs import Supervisor\nwith Supervisor():\n"
                          "    print(signal.getsignal(signal.SIGHUP) is signal.SIG_IGN)"],
                         capture_output=True, text=True, timeout=30)
    assert out.stdout.strip() == "True", out.stderr


def test_leaving_stops_every_process_and_tells_the_reaper_goodbye(mark):
    child = _run_child("""
        a = sup.spawn(["sleep", "60"])
        print(a.pid, sup._reaper.pid, flush=True)
    """, mark)
    pids = [int(p) for p in child.stdout.readline().split()]
    assert child.wait(10) == 0
    assert _wait_dead(pids, 2.0) == []


def test_an_adopted_process_outside_any_group_of_its_own_is_stopped_too():
    with Supervisor(signals=False) as sup:
        p = subprocess.Popen(["sleep", "60"])  # in this process's group: killpg(p.pid) finds no group
        sup.adopt(p)
        t0 = time.monotonic()
        sup.stop([p])
        assert p.returncode == -signal.SIGTERM and time.monotonic() - t0 < 4.0


def test_leaving_stops_the_processes_started_without_spawn_too(mark):
    """A benchmark sweep: a peer run from a thread (subprocess.run), and one that ignores SIGTERM, were
    left running after the command ended: they carry the marker, and leaving stops them (SIGKILL after
    the grace for the one that ignores SIGTERM)."""
    child = _run_child("""
        a = subprocess.Popen(["sleep", "60"], start_new_session=True)
        b = subprocess.Popen(["sh", "-c", "trap '' TERM; sleep 60 & wait; sleep 60"], start_new_session=True)
        print(a.pid, b.pid, flush=True)
        time.sleep(0.3)  # the shell's trap is set
    """, mark)
    pids = [int(p) for p in child.stdout.readline().split()]
    assert len(pids) == 2 and all(_alive(p) for p in pids)
    assert child.wait(15) == 0
    assert _wait_dead(pids, 2.0) == []


def test_a_script_stopped_while_it_waits_on_a_process_it_just_started_stops_that_process(mark):
    """A benchmark sweep: SIGTERM while `start_monitor` waited for the monitor's service (its Popen never
    reached the caller's `finally`) left the monitor running, orphaned; likewise for a Ctrl-C."""
    code = textwrap.dedent(f"""
        import subprocess, sys, time
        sys.path.insert(0, {ROOT!r})
        from rubass_experiments.procs import supervise_script
        supervise_script("bench")
        def start():
            p = subprocess.Popen(["sleep", "60"], start_new_session=True, stdout=subprocess.DEVNULL,
                                 stderr=subprocess.DEVNULL)
            print(p.pid, flush=True)
            time.sleep(60)  # waiting for its service
            return p
        start()
    """)
    child = subprocess.Popen([sys.executable, "-c", code], env=dict(os.environ, **{MARK: mark}),
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    pid = int(child.stdout.readline())
    os.kill(child.pid, signal.SIGTERM)
    assert child.wait(15) == 143
    assert "bench: interrupted by SIGTERM" in child.stderr.read()
    assert _wait_dead([pid], 2.0) == []
