"""Latched actions persisted across the monitor's own death.

ISO 3691-4 forbids an automatic restart after a protective stop: a latched stop that is active
when the monitor dies (SIGKILL, a crash, a power cut of its computer) must be active again when
it is started again (`respawn="true"`), until `~reset`. The file names the latched actions and
the behaviours holding them; it is written (atomically: a temporary file renamed over it) before
a latched action is dispatched, and read before the first tick. A file that cannot be read as
one of ours is reported and treated as "latched" for every action it names (for every latched
action of the spec when it names none): the robot stays stopped rather than restarts. A
latched action the file names that the spec no longer declares (renamed or removed while the
monitor was down) cannot be run: it is `kept` in the file until ~reset, and the monitor withholds
its ~heartbeat meanwhile (`undeclared`; docs/failure-modes.md).

The file is keyed by node name and by master (`master_key`): two monitors of one name on one
machine, each with its own master, never share one. Its "spec" field names the spec that wrote it,
for people: a latch is restored whatever spec the restarted monitor runs (the conservative choice).

No ROS here: the path is given, the format is JSON, so it is tested without a master.
"""
from __future__ import annotations

import json
import os
import re
import threading
from dataclasses import dataclass
from typing import Any, Callable, Dict, Iterable, List, Optional, Sequence, Tuple
from urllib.parse import urlsplit

from ..lang.sourcefile import read_at_most

FORMAT = "rubass-latches"
VERSION = 1


@dataclass(frozen=True)
class Latch:
    """One holder of latched actions: a behaviour (by its label and line) or the monitor itself."""

    holder: str  # "behaviour 2 (line 7)", "overload", "restored …"
    actions: Tuple[str, ...]


DEFAULT_PORT = 11311  # ROS's default master port


def master_key(uri: str, is_local: Callable[[str], bool]) -> str:
    """What names the master in the state file's name: "" for a master on this machine at the
    default port (the name of version 2, so an upgrade keeps its latches), "PORT" for one on this
    machine at another port (localhost, 127.0.0.1 and this machine's name are one master), and
    "HOST.PORT" for a master on another machine (HOST lower-cased, as ROS_MASTER_URI spells it).
    is_local: whether a host name or address is this machine's."""
    parts = urlsplit(uri.strip())
    try:
        port = parts.port or DEFAULT_PORT
        host = (parts.hostname or "").rstrip(".").lower()
    except ValueError:  # no URI rospy could have used; still one file per spelling
        return _safe(uri.strip().lower()) or "unknown-master"
    if not host or is_local(host):
        return "" if port == DEFAULT_PORT else str(port)
    return f"{_safe(host)}.{port}"


def _safe(text: str) -> str:
    return re.sub(r"[^a-z0-9.-]", "_", text)


def default_path(ros_home: Optional[str], node_name: str, master: str = "") -> str:
    """$ROS_HOME/rubass/NODE.latches.json for a master on this machine at the default port, else
    $ROS_HOME/rubass/NODE.MASTER.latches.json with MASTER from master_key (ROS_HOME defaults to
    ~/.ros, as for ROS's own logs)."""
    home = ros_home or os.path.join(os.path.expanduser("~"), ".ros")
    node = node_name.strip("/").replace("/", "_") or "rubass"
    return os.path.join(home, "rubass", node + (f".{master}" if master else "") + ".latches.json")


def adopt_old_default(path: str, old: str) -> bool:
    """Move a latch state file kept under the monitor's former default name (`rubass_monitor`,
    before a plain rosrun was named `rubass`) to `path`, when `path` has none: a stop latched
    before an upgrade survives it. True when it moved."""
    if os.path.exists(path) or not os.path.isfile(old):
        return False
    try:
        os.replace(old, path)
    except OSError:
        return False
    return True


def other_masters(path: str) -> List[str]:
    """When `path` holds no latch: the state files beside it of the same node for other masters
    (or another spelling of one) that hold latches. An engineer who changed ROS_MASTER_URI's host
    spelling between two starts would otherwise lose a protective stop without a word. Sorted."""
    folder, name = os.path.split(path)
    if _holds_latches(path):
        return []
    node = name.split(".", 1)[0]
    try:
        names = sorted(os.listdir(folder))
    except OSError:
        return []
    return [os.path.join(folder, other) for other in names
            if other != name and other.endswith(".latches.json") and other.split(".", 1)[0] == node
            and _holds_latches(os.path.join(folder, other))]


def _holds_latches(path: str) -> bool:
    try:
        with open(path, "rb") as fh:
            latches, error = _parse(read_at_most(fh, 1 << 20))
    except OSError:
        return False
    return bool(latches) and not error


def adopt_unkeyed(path: str, unkeyed: str) -> bool:
    """Copy the state file an earlier version kept for any master (`NODE.latches.json`, which names
    no master) to `path`, this master's, when `path` has none and it holds latches: a stop latched
    before the upgrade survives it. Copied, not moved: were it this machine's default master's too,
    that monitor keeps it (holding a stop twice is the safe error). True when copied."""
    if os.path.exists(path) or not _holds_latches(unkeyed):
        return False
    try:
        with open(unkeyed, "rb") as fh:
            raw = read_at_most(fh, 1 << 20)
        if "master" in json.loads(raw.decode("utf-8")):
            return False  # written by this version for the default master: not ours
        os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
        tmp = f"{path}.{os.getpid()}.tmp"
        with open(tmp, "wb") as fh:
            fh.write(raw)
        os.replace(tmp, path)
    except (OSError, ValueError, UnicodeDecodeError):
        return False
    return True


def load(path: str, declared: Dict[str, bool]) -> Tuple[List[Latch], List[str]]:
    """The latches a previous run left (none if there is no file) and the problems found.

    declared: the spec's action names -> whether each is latched. Actions the file names that
    the spec does not declare cannot be held: they are reported (and `undeclared` lists them).
    """
    try:
        with open(path, "rb") as fh:
            raw = read_at_most(fh, 1 << 20)
    except FileNotFoundError:
        return [], []
    except OSError as exc:
        return _fallback(b"", declared, f"latch state {path} cannot be read ({exc.strerror})")
    latches, error = _parse(raw)
    if error:
        return _fallback(raw, declared, f"latch state {path} is corrupt or foreign ({error})")
    problems = []
    out = []
    for latch in latches:
        known = tuple(a for a in latch.actions if a in declared)
        unknown = [a for a in latch.actions if a not in declared]
        if unknown:
            problems.append(f"latch state {path}: {latch.holder} held {', '.join(unknown)}, which the spec does not "
                            f"declare: cannot hold {'it' if len(unknown) == 1 else 'them'}")
        if known:
            out.append(Latch(latch.holder, known))
    return out, problems


def undeclared(path: str, declared: Dict[str, bool]) -> List[Latch]:
    """The latches of a readable state file whose actions the spec does not declare (only those
    actions): a protective stop the monitor cannot run any more. None for a missing or damaged
    file (a damaged one is read as latching the declared actions it names: `load`)."""
    try:
        with open(path, "rb") as fh:
            raw = read_at_most(fh, 1 << 20)
    except OSError:
        return []
    latches, error = _parse(raw)
    if error:
        return []
    return holders((latch.holder, [a for a in latch.actions if a not in declared]) for latch in latches)


def _parse(raw: bytes) -> Tuple[List[Latch], str]:
    """The latches of a state file's bytes, or why they are not one of ours."""
    try:
        data = json.loads(raw.decode("utf-8"))
        if not isinstance(data, dict) or data.get("format") != FORMAT:
            raise ValueError("not a rubass latch state file")
        if data.get("version") != VERSION:
            raise ValueError(f"written by another version of rubass (version {data.get('version')!r})")
        entries = data["latched"]
        if not isinstance(entries, list):
            raise ValueError("'latched' is not a list")
        latches = []
        for e in entries:
            actions = e["actions"]
            if not isinstance(e["holder"], str) or not isinstance(actions, list) or \
                    not all(isinstance(a, str) for a in actions):
                raise ValueError(f"bad entry {e!r}")
            latches.append(Latch(e["holder"], tuple(actions)))
    except (ValueError, KeyError, TypeError, UnicodeDecodeError) as exc:
        return [], str(exc) or exc.__class__.__name__
    return latches, ""


def _fallback(raw: bytes, declared: Dict[str, bool], why: str) -> Tuple[List[Latch], List[str]]:
    """A file we cannot trust: every declared action it names is latched; if it names none,
    every latched action of the spec is (the safe reading of a damaged protective-stop record)."""
    text = raw.decode("utf-8", errors="replace")
    named = [a for a in declared if re.search(r"(?<![A-Za-z0-9_])" + re.escape(a) + r"(?![A-Za-z0-9_])", text)]
    actions = tuple(named) if named else tuple(a for a, latched in declared.items() if latched)
    if not actions:
        return [], [why + "; it names no action the spec declares"]
    return [Latch("restored from a damaged latch state file", actions)], \
        [why + f"; treated as latched: {', '.join(actions)} (until ~reset)"]


class LatchFile:
    """Writes the latch state when it changes; `path` None turns persistence off."""

    def __init__(self, path: Optional[str], spec_path: str = "", master: str = "") -> None:
        self.path = path
        self.spec_path = spec_path
        self.master = master  # the ROS_MASTER_URI it was written under, for people and `adopt_unkeyed`
        # latches of a previous run that this spec cannot hold (undeclared actions): written with
        # every state until ~reset clears them, so that another restart still knows of them
        self.kept: List[Latch] = []
        self.error = ""  # the last write error, "" when the file is up to date
        self._last: Optional[Tuple[Latch, ...]] = None
        self._lock = threading.Lock()

    def save(self, latches: Sequence[Latch]) -> bool:
        """Write the state if it changed; False (and self.error set) if it could not be written."""
        if self.path is None:
            return True
        state = tuple(sorted(set(latches) | set(self.kept), key=lambda l: (l.holder, l.actions)))
        with self._lock:
            if state == self._last and not self.error:
                return True
            body = json.dumps({"format": FORMAT, "version": VERSION, "spec": self.spec_path, "master": self.master,
                               "latched": [{"holder": l.holder, "actions": list(l.actions)} for l in state]},
                              indent=1)
            tmp = f"{self.path}.{os.getpid()}.tmp"
            try:
                os.makedirs(os.path.dirname(self.path) or ".", exist_ok=True)
                with open(tmp, "w", encoding="utf-8") as fh:
                    fh.write(body)
                os.replace(tmp, self.path)  # survives the process's death from here on
            except OSError as exc:
                folder = os.path.dirname(self.path) or "."
                why = f"{folder} is not a folder" if os.path.exists(folder) and not os.path.isdir(folder) \
                    else (exc.strerror or str(exc))  # makedirs says "File exists" for a file in the way
                self.error = f"cannot write the latch state {self.path}: {why}"
                return False
            self._last, self.error = state, ""
        if state:  # on disk too before a power cut, without holding the engine's thread for it
            threading.Thread(target=_sync, args=(self.path,), name="rubass-latch-sync", daemon=True).start()
        return True


def _sync(path: str) -> None:
    try:
        fd = os.open(path, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
    except OSError:
        pass


def holders(items: Iterable[Tuple[str, Iterable[str]]]) -> List[Latch]:
    """Latch entries from (holder, latched action names), skipping holders with none."""
    return [Latch(h, tuple(a)) for h, a in items if tuple(a)]


__all__: List[Any] = ["Latch", "LatchFile", "adopt_unkeyed", "default_path", "holders", "load", "master_key", "other_masters",
                      "undeclared"]
