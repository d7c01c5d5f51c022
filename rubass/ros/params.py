"""The monitor's private parameters, validated with messages a user can act on."""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Callable, List, Optional, Sequence, Tuple

import yaml

from ..lang.checker import UNUSED_ACTION
from ..lang.errors import Diagnostic, RubassError, did_you_mean
from ..lang.paths import PathError, resolve
from ..lang.units import FREQUENCY, parse_quantity

Getter = Callable[[str, Any], Any]
_MISSING = object()


class ParamError(RubassError):
    """A missing or bad parameter; the message names it and says what is expected."""


@dataclass(frozen=True)
class MonitorConfig:
    spec: str
    actions: List[str] = field(default_factory=list)
    rate: float = 50.0       # scheduler ticks per second
    node_rate: float = 10.0  # node samples per second
    diagnostics_rate: float = 1.0
    master_rate: float = 4.0  # checks per second that the master still knows the monitor
    overload_actions: List[str] = field(default_factory=list)  # run while messages are dropped or seen late
    queue_size: int = 100000  # messages the engine's queue holds
    state_file: Optional[str] = None  # latched actions kept across restarts; None: off
    error_actions: List[str] = field(default_factory=list)  # run while a field cannot be read
    nice: Optional[int] = None  # the threads' nice value (-20 to 19); None: as started (priority.py)
    receiver: str = "one_thread"  # who reads the watched topics: one thread (receiver.py) or "rospy"'s threads
    # ~spec and ~actions paths given relative: ("~spec '../safety.rbs'", the absolute path made from `cwd`,
    # the working directory: $ROS_HOME under roslaunch), for the note a failed read gets (relative_note)
    relative: Tuple[Tuple[str, str], ...] = ()
    cwd: str = ""


KNOWN = ("spec", "actions", "rate", "node_rate", "diagnostics_rate", "master_rate", "overload_actions",
         "queue_size", "error_actions", "state_file", "nice", "receiver")

RECEIVERS = ("one_thread", "rospy")

# `rosrun rubass monitor --help`: each parameter with its type, default and range (read_config checks them)
HELP = """  ~spec (string, required)          the RuBaSS spec to enforce
  ~actions (list of paths, [])      action libraries besides the spec's imports
  ~rate (Hz, 1 to 1000, 50)         scheduler ticks (hold, age/frequency, heartbeat)
  ~node_rate (Hz, 0.1 to 100, 10)   node samples for alive, cpu, memory
  ~diagnostics_rate (Hz, 0.1 to 10, 1)  /diagnostics publications
  ~master_rate (Hz, 0.1 to 100, 4)  checks that the master still knows the monitor
  ~overload_actions (list, [])      actions to run while the monitor drops messages or sees them 0.5 s late
  ~queue_size (int, 10 to 10000000, 100000)  messages the engine's queue holds
  ~error_actions (list, [])         actions to run while a field cannot be read
  ~state_file (path or false, under $ROS_HOME/rubass/)  latched actions kept across the
                                    monitor's restarts; false: none kept (WARN in /diagnostics)
  ~nice (int, -20 to 19, as started)  the monitor's scheduling priority, e.g. -10 on a busy
                                    computer (below the current value: root or CAP_SYS_NICE)
  ~receiver (one_thread or rospy, one_thread)  who reads the watched topics' messages: one
                                    thread for all (less CPU), or a rospy thread per connection
Private parameters stay on the master after the monitor stops: a later rosrun reads them again
(rosparam get /rubass; rosparam delete /rubass/NAME).
"""


def unknown_params(names: List[str], node: str, known: Sequence[str] = KNOWN) -> List[str]:
    """A warning for each private parameter of `node` (full names from the master) that it does
    not read, `known` (a typo such as `_rat:=5` would otherwise be silently ignored)."""
    prefix = node.rstrip("/") + "/"
    # a leaf right under the node; a group deeper down is another node's (an agent in ns="rubass")
    found = sorted({n[len(prefix):] for n in names if n.startswith(prefix) and "/" not in n[len(prefix):]}
                   - set(known) - {""})
    return [f"unknown parameter ~{n} (ignored){did_you_mean('~' + n, ['~' + k for k in known])}" for n in found]


def read_rate(get: Getter, name: str, default: float, lo: float, hi: float) -> float:
    """A rate parameter (a number of Hz, or e.g. '10 Hz') from lo to hi, or ParamError."""
    value = get(name, default)
    q = None
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        q = (float(value), FREQUENCY)
    elif isinstance(value, str):
        q = parse_quantity(value)
    if q is None or (q[1] and q[1] != FREQUENCY) or not lo <= q[0] <= hi:
        raise ParamError(f"~{name} must be a rate from {lo:g} to {hi:g} Hz (a number or e.g. '10 Hz'), "
                         f"got {value!r}")
    return q[0]


def _names(get: Getter, name: str, what: str) -> List[str]:
    """A list param, also accepted as one string separated by commas or spaces, or written as a YAML
    list in one string (`<param name="overload_actions" value="[stop]"/>` hands over "[stop]")."""
    value = get(name, [])
    if isinstance(value, str) and value.strip().startswith("["):
        try:
            value = yaml.safe_load(value)
        except yaml.YAMLError as exc:
            mark = getattr(exc, "problem_mark", None)
            where = f" at column {mark.column + 1}" if mark is not None else ""
            raise ParamError(f"~{name} must be a list of {what}: {value!r} is not a YAML list{where} "
                             f"({getattr(exc, 'problem', None) or exc})") from None
    elif isinstance(value, str):
        value = [a for a in value.replace(",", " ").split() if a]
    if not isinstance(value, list) or not all(isinstance(a, str) and a for a in value):
        raise ParamError(f"~{name} must be a list of {what}, got {value!r}")
    return value


def _path(name: str, value: str, relative: List[Tuple[str, str]]) -> str:
    """A file parameter made absolute: `~` expanded, `package://PKG/…` found on ROS_PACKAGE_PATH, a
    relative path taken from the working directory (noted in `relative`)."""
    written = value
    value = os.path.expanduser(value)
    given_relative = not os.path.isabs(value) and not value.startswith("package://")
    try:  # the working directory only for a relative path (one started in a removed folder still runs)
        path = resolve(value, _cwd(name, written) if given_relative else "/")
    except PathError as exc:
        raise ParamError(f"~{name}: cannot use {written!r}: {exc}") from None
    if given_relative:
        relative.append((f"~{name} {written!r}", path))
    return path


def _cwd(name: str, written: str) -> str:
    try:
        return os.getcwd()
    except OSError:  # the folder it was started in was removed
        raise ParamError(f"~{name}: {written!r} is relative, and the monitor's working directory no longer "
                         f"exists: give an absolute path") from None


def relative_note(config: MonitorConfig) -> str:
    """What a failed read adds when a path was given relative and a file it names is missing: where
    it was looked for (roslaunch starts a node in $ROS_HOME, not in the launch file's folder)."""
    missing = [label for label, path in config.relative if not os.path.exists(path)]
    if not missing:
        return ""
    return (f"({', '.join(missing)} {'is a relative path' if len(missing) == 1 else 'are relative paths'}"
            f", taken from the monitor's working directory {config.cwd}: roslaunch starts a node in $ROS_HOME "
            f"(~/.ros), not in the launch file's folder; write an absolute path, $(find PKG)/… or package://PKG/…)")


def _state_file(get: Getter, default: Optional[str]) -> Optional[str]:
    value = get("state_file", default)
    if value is False or value is None:
        return None
    if not isinstance(value, str) or not value.strip():
        raise ParamError(f"~state_file must be the path of the latch state file, or false to keep no state "
                         f"(a latched stop then does not survive the monitor's restart), got {value!r}")
    return os.path.expanduser(value)


def read_config(get: Getter, default_state_file: Optional[str] = None) -> MonitorConfig:
    """The configuration from a param getter (rospy.get_param with '~' names, or a dict's get);
    default_state_file: where latches are kept when ~state_file is not given."""
    spec = get("spec", _MISSING)
    if spec is _MISSING:
        raise ParamError("~spec is required: the RuBaSS spec to enforce, e.g. "
                         "'rosrun rubass monitor _spec:=/path/to/safety.rbs'")
    if not isinstance(spec, str) or not spec.strip():
        raise ParamError(f"~spec must be the path of a .rbs file, got {spec!r}")
    actions = _names(get, "actions", "action library paths")
    overload = _names(get, "overload_actions", "action names")
    error_actions = _names(get, "error_actions", "action names")
    queue_size = get("queue_size", 100000)
    if not isinstance(queue_size, int) or isinstance(queue_size, bool) or not 10 <= queue_size <= 10_000_000:
        raise ParamError(f"~queue_size must be a whole number of messages from 10 to 10000000, got {queue_size!r}")
    nice = get("nice", None)
    if nice is not None and (not isinstance(nice, int) or isinstance(nice, bool) or not -20 <= nice <= 19):
        raise ParamError(f"~nice must be a whole number from -20 (highest priority) to 19, got {nice!r}")
    receiver = get("receiver", "one_thread")
    if receiver not in RECEIVERS:
        raise ParamError(f"~receiver must be one_thread (one thread reads every watched topic) or rospy (a rospy "
                         f"thread per connection, as rospy subscribers do), got {receiver!r}")
    relative: List[Tuple[str, str]] = []
    return MonitorConfig(
        spec=_path("spec", spec, relative),
        actions=[_path("actions", a, relative) for a in actions],
        rate=read_rate(get, "rate", 50.0, 1.0, 1000.0),
        node_rate=read_rate(get, "node_rate", 10.0, 0.1, 100.0),
        diagnostics_rate=read_rate(get, "diagnostics_rate", 1.0, 0.1, 10.0),
        master_rate=read_rate(get, "master_rate", 4.0, 0.1, 100.0),
        overload_actions=overload,
        queue_size=queue_size,
        state_file=_state_file(get, default_state_file),
        error_actions=error_actions,
        nice=nice,
        receiver=receiver,
        relative=tuple(relative),
        cwd=os.getcwd() if relative else "",  # read above for the first of them
    )


def spec_warnings(warnings: List[Diagnostic], config: MonitorConfig) -> List[Diagnostic]:
    """The spec's warnings that hold for the monitor: an action that only ~overload_actions or
    ~error_actions names is used (by them), not 'declared but never used'."""
    used = {UNUSED_ACTION + a for a in list(config.overload_actions) + list(config.error_actions)}
    return [w for w in warnings if w.subject not in used]
