"""Surviving a master restart.

rospy registers a node's publishers, subscribers and services with the master once, when
each is created, and never again: after the master restarts, the new master does not know
the monitor, so nodes started afterwards (a restarted driver, a new base controller) never
connect to it. Connections made before the restart are peer to peer and keep working.

MasterWatch asks the master, a few times a second, whether it still knows this node
(lookupNode of our own name) and what its process id is (getPid), each with a timeout. It
registers every publisher, subscriber and service of this process again, with the URIs they
already have, and hands each subscription the new master's publisher list, as rospy does at
start-up, at the first poll (the master may have restarted since rospy registered) and
whenever the master
- does not know this node;
- is back after the watch could not reach it; or
- answers from another process than before.
"Knows this node" alone is not enough: a publisher, subscriber or service created while the
master is down (the monitor starting, a reload that names a new topic) makes rospy retry that
one registration until the master is back, and that one registration is enough for the new
master to know the node, while it knows nothing of the others.
Nothing is torn down, so the existing connections, the ones that carry the stop to the
robot's base, are never interrupted.
"""
from __future__ import annotations

import socket
import threading
import time
import xmlrpc.client
from dataclasses import dataclass
from typing import Any, Callable, Optional, Tuple, Union

from rospy.impl.registration import RegManager, get_registration_listeners, get_service_manager, get_topic_manager

from . import rpc
from .reconnect import PERIOD as LOST_PERIOD, LostConnections

Log = Callable[[str, str], None]
MONITOR_UNREACHABLE = ("existing connections keep working and the rules keep being enforced; nodes started now "
                       "cannot connect to the monitor until the master is back")
MONITOR_STARTING_UNREACHABLE = ("the monitor is still starting and enforces nothing yet; what it registers with the "
                                "master (its actions' publishers, its services) waits for the master to be back")


@dataclass
class Registered:
    publishers: int
    subscribers: int
    services: int
    ms: float


def register_all(master: Any, caller_id: str, node_uri: str) -> Registered:
    """Register this process's publishers, subscribers and services with `master` (an XML-RPC
    proxy); connect the subscribers to the publishers it knows. IOError on a refusal."""
    t0 = time.monotonic()
    tm, sm = get_topic_manager(), get_service_manager()
    with tm.lock, sm.lock:  # a consistent list; the calls below are made without the locks
        pubs, subs, srvs = tm.get_publications(), tm.get_subscriptions(), sm.get_services()
    manager = _reg_manager()
    for name, type_name in pubs:
        _ok(master.registerPublisher(caller_id, name, type_name, node_uri), "publisher", name)
    for name, type_name in subs:
        uris = _ok(master.registerSubscriber(caller_id, name, type_name, node_uri), "subscriber", name)
        if manager is not None:
            manager.publisher_update(name, uris)  # rospy connects to new publishers on its own thread
    for name, service_uri in srvs:
        _ok(master.registerService(caller_id, name, service_uri, node_uri), "service", name)
    return Registered(len(pubs), len(subs), len(srvs), (time.monotonic() - t0) * 1000.0)


def _ok(reply: Tuple[int, str, Any], kind: str, name: str) -> Any:
    code, msg, value = reply
    if code != 1:
        raise IOError(f"the master refused to register {kind} {name}: {msg}")
    return value


def _reg_manager() -> Optional[RegManager]:
    for listener in list(get_registration_listeners().listeners):
        if isinstance(listener, RegManager):
            return listener
    return None


class MasterWatch:
    """Polls the master on a thread of its own; re-registers this node when the master has
    forgotten it. `state` and the counters feed the monitor's /diagnostics."""

    def __init__(self, caller_id: str, node_uri: str, master_uri: str, period: float, log: Log,
                 timeout: float = 0.5, unreachable: Union[str, Callable[[], str]] = MONITOR_UNREACHABLE) -> None:
        """`unreachable`: what the warning logged when the master stops answering says it means (or a
        function saying it then)."""
        self.caller_id, self.node_uri, self.master_uri = caller_id, node_uri, master_uri
        self.unreachable = unreachable
        self.period, self.timeout, self.log = period, timeout, log
        self.state = "connected"
        self.reregistrations = 0
        self.down_since: Optional[float] = None  # monotonic time of the first failed poll
        self.master_pid: Optional[int] = None  # the process that answered the last poll
        self._caller = rpc.Caller(master_uri, timeout)  # polled: one kept connection
        # subscriptions whose connection ended while the master lists the publisher (reconnect.py)
        self.lost = LostConnections(caller_id, master_uri, log, timeout, node_uri)
        self._lost_at = 0.0  # when they were last looked for
        self._stop = threading.Event()
        self._thread: Optional[threading.Thread] = None

    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name="rubass-master", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(2.0)
        self._caller.close()
        self.lost.close()

    def _run(self) -> None:
        while not self._stop.wait(self.period):
            try:
                if self.check() != "unreachable" and time.monotonic() - self._lost_at >= LOST_PERIOD:
                    self._lost_at = time.monotonic()
                    manager = _reg_manager()
                    if manager is not None:
                        self.lost.check(manager.publisher_update)
            except Exception as exc:  # never let the watch die: log and poll again
                self.log("error", f"master watch: {exc.__class__.__name__}: {exc}")

    def _unreachable(self, exc: BaseException) -> str:
        first = self.down_since is None
        if first:
            self.down_since = time.monotonic()
        # the state first: with the master's host cut off, rospy's log call itself can block
        # (its /rosout goes there) until the link is back, and /diagnostics must say it meanwhile
        self.state = f"unreachable for {time.monotonic() - self.down_since:.1f} s"
        if first:
            means = self.unreachable() if callable(self.unreachable) else self.unreachable
            self.log("warn", f"the master at {self.master_uri} cannot be reached ({exc}): {means}")
        return "unreachable"

    def check(self) -> str:
        """One poll: 'ok', 'unreachable', 'foreign' (another node holds our name) or 're-registered'."""
        try:
            code, msg, uri = self._caller.call("lookupNode", self.caller_id, self.caller_id)
            pid = self._caller.call("getPid", self.caller_id)[2]
        except (OSError, socket.error, xmlrpc.client.Error) as exc:
            return self._unreachable(exc)
        was_down, self.down_since = self.down_since, None
        was_pid, self.master_pid = self.master_pid, pid
        if code == 1 and uri != self.node_uri:  # rospy shuts a node down when another takes its name: no fight
            self.state = f"another node ({uri}) holds the name {self.caller_id}"
            return "foreign"
        if code == 1 and was_down is None and was_pid == pid:
            self.state = "connected"
            return "ok"
        why = ("did not know this node (it restarted)" if code != 1 else
               "is back after being unreachable" if was_down is not None else
               "" if was_pid is None else  # the first poll: the master may have restarted since rospy registered
               f"answers from another process (pid {was_pid}, now {pid}: it restarted)")
        try:
            reg = register_all(rpc.proxy(self.master_uri, self.timeout), self.caller_id, self.node_uri)
        except Exception as exc:
            self.master_pid = was_pid  # not done: the next poll tries again
            if was_down is not None:
                self.down_since = was_down
            if isinstance(exc, (ConnectionError, socket.timeout)):  # it went away meanwhile: said as such
                return self._unreachable(exc)
            raise
        self.state = "connected"
        if not why:
            self.log("debug", f"the master at {self.master_uri} (pid {pid}) has every registration of this node "
                              f"({reg.ms:.1f} ms)")
            return "ok"
        self.reregistrations += 1
        self.log("warn", f"the master at {self.master_uri} {why}: registered {reg.publishers} publishers, "
                         f"{reg.subscribers} subscribers and {reg.services} services again in {reg.ms:.1f} ms")
        return "re-registered"
