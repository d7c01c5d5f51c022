"""`rosrun rubass monitor`: the monitor node's entry point (rubass/ros/monitor.py holds the node).
Parameters are read and checked here; a bad one is a FATAL line and exit 1, never a traceback."""
from __future__ import annotations

import os
import signal
import sys
from typing import List, Optional

import rosgraph
import rospy

from ..actions.latches import adopt_old_default, adopt_unkeyed, default_path, master_key
from .exiting import exit_within
from .latch_master import is_local
from .monitor import ConfigError, Monitor
from .params import HELP, ParamError, read_config, unknown_params
from .priority import set_nice
from .rosout_param import keep_rosout_flag
from .startup import STOP_GRACE, MasterLost, init_node, private_param, stop_asked, wants_help

USAGE = ("usage: rosrun rubass monitor _spec:=SPEC.rbs [_actions:=LIBRARY.yaml] [_NAME:=VALUE ...]\n"
         "The rubass monitor node: enforces the rules of SPEC on the live system until stopped (SIGINT/SIGTERM);\n"
         "SIGHUP or the ~reload service reloads them. Private parameters (type, range, default; docs/monitor.md):\n"
         + HELP + "Check a spec first with: rubass check SPEC.rbs --actions LIBRARY.yaml\n")


_EARLY_SIGHUP = b"rubass: SIGHUP before the monitor started: nothing to reload yet (the spec is read when it starts)\n"


def early_sighup(signum: int, frame: object) -> None:
    """SIGHUP while the monitor waits for the master: said, nothing else (os.write: see main). Its own
    handler is in place before it reads the spec (Monitor.setup)."""
    os.write(2, _EARLY_SIGHUP)


def main(argv: Optional[List[str]] = None) -> int:
    if wants_help(argv):
        sys.stdout.write(USAGE)
        return 0
    # SIGHUP reloads once the monitor runs (its handler replaces this one); before, its default would end it.
    # os.write, not sys.stderr: a signal that lands inside a write to sys.stderr (the "waiting for the
    # ROS master" line) would make that write reentrant, a RuntimeError that ended the process
    signal.signal(signal.SIGHUP, early_sighup)
    code = init_node("rubass", argv, lambda text: sys.stderr.write(f"rubass: {text}\n"))
    if code is not None:
        return code  # Monitor handles SIGINT/SIGTERM once it runs; before, a signal ends the wait for the master
    keep_rosout_flag()  # no log call asks the master anything (one would block while its host is cut off)
    sys.setswitchinterval(0.0005)  # a busy thread must not delay a deadline by the default 5 ms
    try:
        names = rospy.get_param_names()
    except Exception:  # noqa: BLE001 - only a warning is lost; read_config says what is wrong
        names = []
    for warning in unknown_params(names, rospy.get_name()):  # a typo must not pass silently
        rospy.logwarn("rubass: %s", warning)
    # one file per node name and master: two monitors of two masters on one machine share none
    master = master_key(rosgraph.get_master_uri(), is_local)
    state_file = default_path(os.environ.get("ROS_HOME"), rospy.get_name(), master)
    if rospy.get_name() == "/rubass" and not master:  # a plain rosrun was /rubass_monitor before version 2's last stop
        old = default_path(os.environ.get("ROS_HOME"), "/rubass_monitor")
        if adopt_old_default(state_file, old):
            rospy.logwarn("rubass: latch state %s moved to %s (the node's new default name)", old, state_file)
    if master:  # an earlier version kept one file for any master: a stop latched before the upgrade survives it
        unkeyed = default_path(os.environ.get("ROS_HOME"), rospy.get_name())
        if adopt_unkeyed(state_file, unkeyed):
            rospy.logwarn("rubass: latch state %s (kept by an earlier version for any master) copied to %s, "
                          "this master's", unkeyed, state_file)
    try:
        config = read_config(private_param, state_file)
        refused = set_nice(config.nice) if config.nice is not None else None  # before the monitor's threads
        if refused:  # start: they inherit it
            rospy.logwarn("rubass: %s", refused)
        elif config.nice is not None:
            rospy.loginfo("rubass: running at nice %d (~nice)", config.nice)
        monitor = Monitor(config)
        monitor.nice_refused = bool(refused)
        monitor.setup()  # its SIGINT/SIGTERM handlers replace init_node's, which only note a signal
        if stop_asked():  # one came before: it stops now, as its own handlers would have it
            monitor.request_stop()
    except (ParamError, ConfigError) as exc:
        rospy.logfatal("rubass: cannot start:\n%s", exc)  # on stderr and in rosout: printed once
        rospy.signal_shutdown("cannot start")
        return 1
    except MasterLost as exc:  # as when it goes away during init_node: one line, exit 1
        rospy.logfatal("rubass: cannot start: %s; nothing was enforced", exc)
        exit_within(STOP_GRACE, 1, "nothing had been started")  # rospy's shutdown may wait for the master
        rospy.signal_shutdown("cannot start")
        return 1
    monitor.run()
    return 0
