"""Is the pid a node gives the process we can measure? A check of its XML-RPC port.

A node in a PID namespace of its own (a Docker container, `unshare --pid`) answers getPid
with its pid *in that namespace* (often 1): measuring that pid on this host measures another
process (init), and a CPU hog would read idle. The process that really serves the node
listens on the port of its XML-RPC URI; so before measuring, NodeSampler asks whether the pid
owns that port: its TCP sockets in LISTEN (psutil). Where the process's sockets may not be
read (AccessDenied), every process's listening sockets are read instead; if neither says
who listens, the pid is measured as before (docs/multihost.md). One check per (URI, pid).
"""
from __future__ import annotations

import threading
from typing import Any, Dict, Iterable, Optional, Tuple
from urllib.parse import urlparse

import psutil

_OTHER_NS = "the node runs in another PID namespace (a container?); cannot measure it"


def _listens(conns: Iterable[Any], port: int) -> Iterable[Any]:
    """The pids (None where unreadable) of the sockets in `conns` listening on `port`."""
    return [getattr(c, "pid", None) for c in conns
            if c.status == psutil.CONN_LISTEN and c.laddr and tuple(c.laddr)[1] == port]


def _process_tcp(pid: int) -> Any:
    proc = psutil.Process(pid)
    get = getattr(proc, "net_connections", None) or proc.connections  # psutil >= 6 renamed it
    return get(kind="tcp")


class PortOwners:
    """Verdicts per (URI, pid): None if the pid may be measured, else why not. Thread-safe."""

    MAX_KEPT = 4096  # verdicts kept; beyond, the cache starts again (nodes restarting for days)

    def __init__(self) -> None:
        self._verdicts: Dict[Tuple[str, int], Optional[str]] = {}
        self._lock = threading.Lock()

    def why_not(self, node: str, uri: str, pid: int) -> Optional[str]:
        key = (uri, pid)
        with self._lock:
            if key in self._verdicts:
                return self._verdicts[key]
        verdict, final = self._check(node, uri, pid)
        if final:
            with self._lock:
                if len(self._verdicts) >= self.MAX_KEPT:
                    self._verdicts.clear()
                self._verdicts[key] = verdict
        return verdict

    def _check(self, node: str, uri: str, pid: int) -> Tuple[Optional[str], bool]:
        """(verdict, whether to keep it)."""
        try:
            port = urlparse(uri).port
        except ValueError:
            port = None
        if port is None:
            return None, True  # no port to check: measured as before
        try:
            owners = _listens(_process_tcp(pid), port)
        except (psutil.NoSuchProcess, psutil.ZombieProcess):
            return (f"pid {pid} that {node} reports is no process of this host (or it just exited): {_OTHER_NS}",
                    False)
        except psutil.AccessDenied:
            return self._by_system(node, pid, port), True
        if owners:
            return None, True
        return f"pid {pid} that {node} reports does not listen on its port {port}: {_OTHER_NS}", True

    @staticmethod
    def _by_system(node: str, pid: int, port: int) -> Optional[str]:
        """Who listens on `port`, from every process's sockets (those it may read)."""
        try:
            owners = set(_listens(psutil.net_connections(kind="tcp"), port))
        except (psutil.AccessDenied, OSError):
            return None
        others = sorted(p for p in owners if p is not None and p != pid)
        if pid in owners or not others:
            return None  # it does, or nobody can tell: measured as before
        return (f"pid {pid} that {node} reports does not listen on its port {port} (pid {others[0]} does): "
                f"{_OTHER_NS}")
