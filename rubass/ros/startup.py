"""A node's start, before it protects anything: `--help`, and rospy.init_node's wait for a master
that is not up yet, which SIGINT or SIGTERM must end with one line, not a traceback."""
from __future__ import annotations

import signal
import sys
import time
from typing import Any, Callable, List, Optional

from .exiting import EXIT_GRACE, exit_within


class _Stopped(BaseException):
    """A signal ended the wait for the master: a BaseException, so that rospy's `except Exception`
    around its retries lets it through."""


STOP_GRACE = 1.0  # s: nothing was started, so rospy gets this long to shut down before the process exits


class MasterLost(Exception):
    """The master stopped answering after init_node, while the node read its parameters (a traceback
    before): the message says so, for a `cannot start:` line."""


def private_param(name: str, default: Any) -> Any:
    """rospy.get_param("~NAME", default); MasterLost when the master does not answer."""
    import rosgraph
    import rospy

    try:
        return rospy.get_param("~" + name, default)
    except OSError as exc:
        raise MasterLost(f"the ROS master at {rosgraph.get_master_uri()} stopped answering while the parameters "
                         f"were read (~{name}: {exc.strerror or exc})") from None


def keep_console_log() -> bool:
    """Print the node's log lines on the console even when rospy could not set up its logging. It
    cannot when its log folder cannot be made (ROS_LOG_DIR unwritable, or another user's folder
    above it: rospy gives the new folder its parent's owner): it then prints one WARNING and sends
    every later line to /rosout only, so a monitor that cannot enforce its spec said nothing where
    it was started. True when the console handler had to be added."""
    import logging

    from rosgraph.roslogging import RosStreamHandler

    rosout = logging.getLogger("rosout")
    if any(isinstance(h, RosStreamHandler) for h in rosout.handlers):
        return False
    handler = RosStreamHandler()
    handler.setFormatter(logging.Formatter("[%(name)s][%(levelname)s] %(asctime)s: %(message)s"))
    rosout.addHandler(handler)
    if rosout.level == logging.NOTSET or rosout.level > logging.INFO:
        rosout.setLevel(logging.INFO)  # as ROS's logging configuration sets it
    return True


def null_params(argv: List[str]) -> List[str]:
    """The private parameters `_NAME:=VALUE` of a command line whose value YAML reads as null."""
    import yaml

    out = []
    for arg in argv[1:]:
        name, sep, value = arg.partition(":=")
        if sep and name.startswith("_") and not name.startswith("__"):
            try:
                if yaml.safe_load(value) is None:
                    out.append(name[1:])
            except yaml.YAMLError:
                continue
    return out


def wants_help(argv: Optional[List[str]]) -> bool:
    """Whether the command line asks for help (ROS remappings `name:=value` aside)."""
    args = sys.argv[1:] if argv is None else argv[1:]
    return any(a in ("-h", "--help", "help") for a in args if ":=" not in a)


def init_node(name: str, argv: Optional[List[str]], say: Callable[[str], None]) -> Optional[int]:
    """rospy.init_node, after waiting for the master as long as it does not answer. None once the node
    is up (without rospy's SIGINT/SIGTERM handlers: until the node installs its own, one is noted for
    stop_asked()); else the exit code, after `say` has told why: 0 when SIGINT or SIGTERM ended the wait,
    1 when the master went away during the start. rospy is then shut down, and the process exits within
    STOP_GRACE seconds even if rospy's shutdown waits for the master."""
    import rosgraph
    import rospy

    uri = rosgraph.get_master_uri()
    stopped: List[int] = []

    def stop(signum: int, _frame: object) -> None:
        # Not rospy's handler: it shuts rospy down on this (the main) thread, which holds the topic
        # manager's lock while it retries the master, and the shutdown waits for that lock: for good.
        stopped.append(signum)
        raise _Stopped(signum)

    previous = {s: signal.signal(s, stop) for s in (signal.SIGINT, signal.SIGTERM)}
    failed = ""
    answered = False
    try:
        _wait_for_master(uri, say, stopped)  # rospy waits only if no _param:= is given; with one it raises at once
        answered = True
        rospy.init_node(name, argv=argv, disable_signals=True)
    except _Stopped:
        pass
    except OSError as exc:  # the master went away between our wait and rospy's calls
        failed = f"the ROS master at {uri} stopped answering during the start ({exc.strerror or exc})"
    except rospy.exceptions.ROSInitException as exc:  # rospy's words for a master that went away: ours
        if not (stopped or rospy.is_shutdown()):
            failed = (f"cannot start: {exc}" if master_answers(uri) else
                      f"the ROS master at {uri} stopped answering during the start ({exc})")
    except TypeError as exc:  # rospy stores each _NAME:= on the master; XML-RPC has no null
        nulls = null_params(sys.argv if argv is None else argv)
        failed = (f"cannot start: {', '.join('~' + n for n in nulls)}: null is no parameter value (the master "
                  f"cannot store it); leave the parameter out for its default" if nulls else f"cannot start: {exc}")
    finally:
        up = not (stopped or failed or rospy.is_shutdown())
        for s, handler in previous.items():  # up: noted until the node's own (the imports' would exit
            signal.signal(s, _ask_stop if up else handler)  # at once, its registrations left on the master)
    if up:
        keep_console_log()
        return None
    say(failed or (f"stopped while starting (the ROS master at {uri} had answered); nothing was enforced" if answered
                   else f"stopped before the ROS master at {uri} answered; nothing was started"))
    code = 1 if failed else 0
    exit_within(STOP_GRACE, code, "nothing had been started")
    rospy.signal_shutdown("stopped before start")
    return code


MASTER_CHECK_TIMEOUT = 1.0  # s: a master that accepts connections but does not answer (paused, hung) is not up


def master_answers(uri: str) -> bool:
    """Whether the master at `uri` answers getPid within MASTER_CHECK_TIMEOUT: rosgraph.is_master_online
    had no timeout (a paused master held the wait, and its "waiting" line, for good) and a bare
    `except`, which swallowed the exception a stop signal's handler raised inside it (the signal was lost)."""
    from .rpc import Caller

    try:
        code, _, _ = Caller(uri, MASTER_CHECK_TIMEOUT, keep_alive=False).call("getPid", "/rubass")
    except Exception:  # noqa: BLE001 - refused, timed out, a bad URI or answer: not up (a signal's BaseException passes)
        return False
    return code == 1


_ASKED: List[int] = []  # SIGINT/SIGTERM after the node is up, before it installed its own handlers


def _ask_stop(signum: int, _frame: object) -> None:
    """Noted for the node's own handlers; should it never get there (a master that hangs while the
    parameters are read: rospy's calls have no timeout), the process exits after EXIT_GRACE seconds."""
    _ASKED.append(signum)
    exit_within(EXIT_GRACE, 0, "nothing had been started", "the node did not reach its own stop")


def stop_asked() -> bool:
    """Whether SIGINT or SIGTERM came between init_node's return and the node's own handlers: the node
    stops as soon as those are in place (cleanly: released, unregistered)."""
    return bool(_ASKED)


def _wait_for_master(uri: str, say: Callable[[str], None], stopped: List[int]) -> None:
    """Until the master at `uri` answers or a signal ends the wait (its handler raises, and records it in
    `stopped`, should any library code still swallow what it raised: the wait went on for good once)."""
    said = False
    while not stopped and not master_answers(uri):
        if not said:
            say(f"waiting for the ROS master at {uri} (is roscore running? is ROS_MASTER_URI right?)")
            said = True
        if not stopped:
            time.sleep(0.5)
    if stopped:
        raise _Stopped(stopped[0])
