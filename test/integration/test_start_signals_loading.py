"""Signals in the monitor's start, after the master answered and before it enforces (an acceptance sweep
of process lifecycles): a SIGHUP while the spec was read was said ("nothing to reload yet") and dropped,
so an edit saved then was never enforced; a SIGTERM then killed the process with no line, its node left
registered; a master that accepted connections but never answered (paused) held the start with no
"waiting" line; a signal during rospy's own start said the master had not answered; and a SIGINT while
waiting for /clock logged a first /clock message and "enforcing"."""
import os
import signal
import subprocess
import sys
import time

import pytest

import rosharness
from conftest import ROOT

pytestmark = pytest.mark.ros

PY = "/usr/bin/python3"


def _big_spec(path, limit=1, rules=6000, watchdog=False):
    """A spec that takes about a second to read here, with one real rule: /speed over `limit` brakes, or
    (`watchdog`) /cmd_vel silent for 1 s stops, which needs no master."""
    lines = ['import "lib.yaml";', "action primitive stop, brake, warn;", "entity f { rules:"]
    lines += [f"  r{i}: topic /filler{i % 50}.data > {i};" for i in range(rules)]
    lines += ["}"] + (["entity base { rules: stale: age(topic /cmd_vel) > 1 s; }", "if (base.stale) then { stop; }"]
                      if watchdog else [f"entity base {{ rules: fast: topic /speed.data > {limit}; }}",
                                        "if (base.fast) then { brake; }"])
    path.write_text("\n".join(lines) + "\n")


def _monitor_reading(ros, tmp_path, lib=None, **spec):
    """A monitor started on a big spec (`_big_spec(**spec)`), returned once its node is registered: it
    reads the spec for about a second next. Its spec's path too."""
    (tmp_path / "lib.yaml").write_text(lib or rosharness.LIB)
    path = tmp_path / "s.rbs"
    _big_spec(path, **spec)
    mon = ros.monitor(str(path), wait=False)
    _wait_registered(ros, mon)
    return mon, path


LONG = 20000  # rules: read in about a second on an idle machine (6,000 took 0.3 s, and the master was stopped late)


def _lose_the_master_while_the_spec_is_read(ros):
    """For a monitor reading a spec of LONG rules: the parameters are read by then (a few ms)."""
    time.sleep(0.3)
    ros.master.stop()


def _registered(ros, name="/rubass"):
    import rosgraph

    try:
        state = rosgraph.Master("/t", master_uri=ros.env["ROS_MASTER_URI"]).getSystemState()
    except Exception:  # noqa: BLE001
        return False
    return any(name in nodes for _, nodes in state[0] + state[1] + state[2])


def _wait_registered(ros, proc, timeout=20.0):
    end = time.time() + timeout
    while not _registered(ros) and time.time() < end:
        assert proc.poll() is None, ros.log(proc)
        time.sleep(0.01)
    assert _registered(ros), ros.log(proc)


def _speed_brakes(ros, value):
    rec = ros.probe({"listen": [{"topic": "/brake", "type": "std_msgs/Bool"}],
                     "advertise": [{"topic": "/speed", "type": "std_msgs/Float64"}],
                     "steps": [{"wait_subscribers": "/speed"}, {"sleep": 0.3},
                               {"publish": "/speed", "msg": {"data": value}}, {"sleep": 1.0}]})
    return any(r["kind"] == "recv" and r["topic"] == "/brake" for r in rec)


def test_an_edit_saved_and_signalled_while_the_spec_is_read_is_enforced(ros, tmp_path):
    mon, spec = _monitor_reading(ros, tmp_path, limit=100)  # lenient
    time.sleep(0.1)  # reading the spec now (about a second)
    _big_spec(spec, 1)  # the engineer's stricter edit, saved, then SIGHUP
    mon.send_signal(signal.SIGHUP)
    rosharness.wait_log(mon, ros, "rubass: enforcing", timeout=30)
    # the line "reload (SIGHUP) asked while the monitor starts" comes before "enforcing": wait for the
    # reload itself, which takes a few seconds for 6,000 rules on a loaded machine
    rosharness.wait_log(mon, ros, "(SIGHUP, asked while the monitor started)", timeout=60)
    assert "rubass: reloaded " in ros.log(mon), ros.log(mon)
    assert _speed_brakes(ros, 2.0), ros.log(mon)  # 2 > 1: the edit holds (with the first spec, 2 < 100)
    assert "nothing to reload yet" not in ros.log(mon), ros.log(mon)


def test_a_sigterm_while_the_spec_is_read_ends_the_monitor_cleanly_and_unregistered(ros, tmp_path):
    mon, _ = _monitor_reading(ros, tmp_path, limit=100)
    time.sleep(0.1)
    mon.send_signal(signal.SIGTERM)
    assert mon.wait(20) == 0, ros.log(mon)  # was -15, no line
    assert "stopping (nothing was enforced)" in ros.log(mon), ros.log(mon)
    assert "Traceback" not in ros.log(mon)
    assert not _registered(ros), "the monitor's node is still registered with the master"


def test_a_paused_master_gets_the_waiting_line_and_the_monitor_enforces_once_it_answers(ros, tmp_path):
    os.kill(ros.master.process.pid, signal.SIGSTOP)  # accepts connections, answers nothing
    try:
        mon = ros.monitor(rosharness.spec(tmp_path, "entity base { rules: fast: topic /speed.data > 1; }\n"
                                                    "if (base.fast) then { brake; }\n"), wait=False)
        rosharness.wait_log(mon, ros, f"waiting for the ROS master at {ros.env['ROS_MASTER_URI']}", timeout=10)
    finally:
        os.kill(ros.master.process.pid, signal.SIGCONT)
    ros.wait_service("/rubass/reset", mon, timeout=20)
    assert _speed_brakes(ros, 2.0), ros.log(mon)


def _started_with(code):
    """Run `code` in a process where the master answered (no master needed) and startup is imported."""
    head = ("import os, signal, sys, time\nimport rospy\nimport rubass.ros.startup as startup\n"
            "startup.master_answers = lambda uri: True  # it answered\n")
    env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:1", PYTHONDONTWRITEBYTECODE="1")
    return subprocess.run([sys.executable, "-c", head + code], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=30)


def test_a_signal_after_rospys_start_before_the_nodes_own_handlers_is_kept_for_them():
    """A re-sweep: in the few ms after init_node, the imports' handler ran (exit 143 at once, "stopped while
    loading", the node's registrations left on the master)."""
    out = _started_with("rospy.init_node = lambda *a, **k: None\n"
                        "signal.signal(signal.SIGTERM, lambda s, f: sys.exit(143))  # as scripts/monitor has it\n"
                        "assert startup.init_node('probe', ['probe'], print) is None\n"
                        "os.kill(os.getpid(), signal.SIGTERM)\nprint('alive', startup.stop_asked())\n")
    assert (out.returncode, out.stdout) == (0, "alive True\n"), (out.stdout, out.stderr)


def test_a_signal_during_rospys_own_start_does_not_say_the_master_never_answered():
    out = _started_with("def init_node(*a, **k):\n    os.kill(os.getpid(), signal.SIGTERM)\n    time.sleep(0.05)\n"
                        "rospy.init_node = init_node\n"
                        "sys.exit(startup.init_node('probe', ['probe'], lambda t: sys.stderr.write(t + '\\n')))\n")
    assert out.returncode == 0, out.stderr
    assert "stopped while starting (the ROS master at http://127.0.0.1:1 had answered); nothing was enforced" \
        in out.stderr, out.stderr
    assert "before the ROS master" not in out.stderr


def test_a_master_lost_inside_rospys_start_is_named_not_rospys_failed_to_initialize_time():
    """A re-sweep: rospy wraps the socket error of a master that went away during its start as "Failed to
    initialize time. Please check logs", which was all the monitor and the agent said."""
    out = _started_with("answers = iter([True])\nstartup.master_answers = lambda uri: next(answers, False)\n"
                        "def init_node(*a, **k):\n"
                        "    raise rospy.exceptions.ROSInitException('Failed to initialize time. Please check logs')\n"
                        "rospy.init_node = init_node\n"
                        "sys.exit(startup.init_node('probe', ['probe'], lambda t: sys.stderr.write(t + '\\n')))\n")
    assert out.returncode == 1, out.stderr
    assert "the ROS master at http://127.0.0.1:1 stopped answering during the start (Failed to initialize time" \
        in out.stderr, out.stderr


def test_a_stop_asked_while_a_hung_master_holds_the_parameters_ends_the_process():
    """A re-sweep: a master that hangs (SIGSTOP) after init_node held rospy's parameter calls, which have no
    timeout, and the SIGTERM noted for the node's own handlers never got there: only SIGKILL ended it."""
    t0 = time.monotonic()
    out = _started_with("rospy.init_node = lambda *a, **k: None\n"
                        "assert startup.init_node('probe', ['probe'], print) is None\n"
                        "os.kill(os.getpid(), signal.SIGTERM)\ntime.sleep(25)  # rospy.get_param on a hung master\n")
    assert out.returncode == 0 and time.monotonic() - t0 < 15, out.stderr
    assert "[rubass] the node did not reach its own stop within 5 s" in out.stderr, out.stderr


def test_a_sigterm_while_the_start_waits_for_the_master_ends_the_monitor(ros, tmp_path):
    """A re-sweep: a SIGTERM while the actions' publishers waited for a master that was down was kept
    until the master came back (27 s and more; for good if it never did)."""
    mon, _ = _monitor_reading(ros, tmp_path, rules=LONG)
    _lose_the_master_while_the_spec_is_read(ros)
    rosharness.wait_log(mon, ros, "setting up the actions takes over a second", timeout=30)
    t0 = time.monotonic()
    mon.send_signal(signal.SIGTERM)
    assert mon.wait(15) == 0, ros.log(mon)
    assert time.monotonic() - t0 < 10
    assert "the monitor's start did not stop within 5 s" in ros.log(mon) and "nothing was enforced" in ros.log(mon)


@pytest.mark.parametrize("reload_first", [False, True], ids=["", "after-a-reload"])
def test_sigint_while_waiting_for_the_first_clock_says_no_clock_came(ros, tmp_path, reload_first):
    import rosgraph

    rosgraph.Master("/t", master_uri=ros.env["ROS_MASTER_URI"]).setParam("/use_sim_time", True)
    mon = ros.monitor(rosharness.spec(tmp_path, "entity base { rules: fast: topic /speed.data > 1; }\n"
                                                "if (base.fast) then { brake; }\n"), wait=False)
    rosharness.wait_log(mon, ros, "no /clock message has come yet", timeout=20)
    if reload_first:  # asked while it waits for /clock: dropped when it stops before enforcing (it was run
        mon.send_signal(signal.SIGHUP)  # on an engine that did not exist: AttributeError, "previous rules")
        rosharness.wait_log(mon, ros, "asked while the monitor starts", timeout=10)
    mon.send_signal(signal.SIGINT)
    assert mon.wait(20) == 0, ros.log(mon)
    time.sleep(0.2)
    log = ros.log(mon)
    assert "first /clock message" not in log and "rubass: enforcing" not in log, log
    assert "stopping" in log and "Error" not in log and "previous rules" not in log, log


LOG_LIB = """actions:
  stop: {plugin: log, level: warn, message: STOP-LOGGED}
  brake: {plugin: log, level: warn, message: BRAKE-LOGGED}
  warn: {plugin: log, level: warn, message: WARN-LOGGED}
"""


def test_a_master_lost_while_the_spec_is_read_does_not_hold_the_rules_unenforced(ros, tmp_path):
    """CI found it: a master that went down in the monitor's start, after the spec was read, held the
    start in rospy's registration of ~reload (and of the agents' topic) until the master came back: no
    rule was enforced meanwhile, while the master watch said "the rules keep being enforced"."""
    mon, _ = _monitor_reading(ros, tmp_path, LOG_LIB, rules=LONG, watchdog=True)
    _lose_the_master_while_the_spec_is_read(ros)
    rosharness.wait_log(mon, ros, "rubass: enforcing", timeout=30)
    rosharness.wait_log(mon, ros, "STOP-LOGGED", timeout=10)  # the watchdog, with the master still down
    assert "the rules keep being enforced" not in ros.log(mon).split("rubass: enforcing")[0], ros.log(mon)
    ros.master.restart()
    ros.wait_service("/rubass/reset", mon, timeout=20)  # registered once the master is back
    assert mon.poll() is None, ros.log(mon)


def test_a_master_lost_before_the_actions_are_set_up_is_said_and_enforcing_follows_its_return(ros, tmp_path):
    """Publish actions register with the master; while it is down the start waits there: said, with NO
    RULE IS ENFORCED (rospy said only "Unable to register"), and enforcing follows the master's return."""
    mon, _ = _monitor_reading(ros, tmp_path, rules=LONG)
    _lose_the_master_while_the_spec_is_read(ros)
    rosharness.wait_log(mon, ros, "setting up the actions takes over a second", timeout=30)
    log = ros.log(mon)
    assert "NO RULE IS ENFORCED until it is done" in log and "rubass: enforcing" not in log, log
    ros.master.restart()
    rosharness.wait_log(mon, ros, "rubass: enforcing", timeout=30)
    ros.wait_service("/rubass/reset", mon, timeout=20)
    assert _speed_brakes(ros, 2.0), ros.log(mon)
