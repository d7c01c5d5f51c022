"""Several "hosts" on this machine for multi-host tests: network namespaces on one switch.

Each host is a namespace with `lo` and one interface `eth0` (a veth pair whose other end is
on a bridge in a "switch" namespace), at 10.200.0.N/24. Those addresses exist only inside
the namespaces made here, so no traffic leaves them. `cut(host)` takes the host's link down
on the switch side (the cable pulled); `close()` stops what still runs in them and deletes
every namespace (and with them their veths and the bridge). Namespace names carry this
process's pid: leftovers of a killed test run are removed by the next run. Needs root and
iproute2; `Network.check()` says why not.
"""
import os
import re
import shutil
import signal
import subprocess
from typing import Dict, List, Set

PREFIX = "rbmh"
SUBNET = "10.200.0"


def _ip(*args: str, check: bool = True) -> subprocess.CompletedProcess:
    out = subprocess.run(["ip", *args], capture_output=True, text=True, timeout=20)
    if check and out.returncode != 0:
        raise RuntimeError(f"ip {' '.join(args)}: {out.stderr.strip()}")
    return out


def _namespaces() -> List[str]:
    out = _ip("netns", "list", check=False)
    return [line.split()[0] for line in out.stdout.splitlines() if line.strip()]


def _delete(ns: str) -> None:
    """Stop what still runs in a namespace of ours (SIGKILL), then delete it."""
    for pid in _ip("netns", "pids", ns, check=False).stdout.split():
        try:
            os.kill(int(pid), signal.SIGKILL)
        except (ProcessLookupError, ValueError):
            pass
    _ip("netns", "del", ns, check=False)


def remove_leftovers() -> None:
    """Delete namespaces left by test runs whose process is gone (killed before cleaning up)."""
    for ns in _namespaces():
        m = re.match(rf"{PREFIX}(\d+)_", ns)
        if m and not os.path.exists(f"/proc/{m.group(1)}"):
            _delete(ns)


class Network:
    """Hosts by name (e.g. robot, gpu, monitor), each at an address of SUBNET."""

    def __init__(self, hosts: List[str]) -> None:
        self.tag = f"{PREFIX}{os.getpid()}_"
        self.switch = self.tag + "sw"
        self.ns: Dict[str, str] = {h: self.tag + h for h in hosts}
        self.address: Dict[str, str] = {h: f"{SUBNET}.{i + 1}" for i, h in enumerate(hosts)}
        self._ports: Dict[str, str] = {h: f"p{i}" for i, h in enumerate(hosts)}
        self._made: List[str] = []
        self.cut_hosts: Set[str] = set()

    @staticmethod
    def check() -> str:
        """Why namespaces cannot be made here ('' if they can)."""
        if os.geteuid() != 0:
            return "network namespaces need root (ip netns add)"
        if shutil.which("ip") is None:
            return "the ip command (Debian package iproute2) is not installed"
        probe = f"{PREFIX}{os.getpid()}_probe"
        out = _ip("netns", "add", probe, check=False)
        if out.returncode != 0:
            return f"ip netns add fails here: {out.stderr.strip()}"
        _ip("netns", "del", probe, check=False)
        return ""

    def setup(self) -> None:
        """Make the switch and the hosts; on any failure, remove what was made and raise."""
        remove_leftovers()
        try:
            self._add(self.switch)
            _ip("-n", self.switch, "link", "add", "br0", "type", "bridge")
            _ip("-n", self.switch, "link", "set", "br0", "up")
            for host, ns in self.ns.items():
                self._add(ns)
                port = self._ports[host]
                _ip("link", "add", "eth0", "netns", ns, "type", "veth", "peer", "name", port, "netns", self.switch)
                _ip("-n", self.switch, "link", "set", port, "master", "br0")
                _ip("-n", self.switch, "link", "set", port, "up")
                _ip("-n", ns, "addr", "add", f"{self.address[host]}/24", "dev", "eth0")
                _ip("-n", ns, "link", "set", "eth0", "up")
        except Exception:
            self.close()
            raise

    def _add(self, ns: str) -> None:
        _ip("netns", "add", ns)
        self._made.append(ns)
        _ip("-n", ns, "link", "set", "lo", "up")

    def cmd(self, host: str, args: List[str]) -> List[str]:
        """`args` run on `host` (inside its namespace)."""
        return ["ip", "netns", "exec", self.ns[host], *args]

    def cut(self, host: str) -> None:
        """Pull the host's cable: its switch port (its veth's far end) goes down."""
        _ip("-n", self.switch, "link", "set", self._ports[host], "down")
        self.cut_hosts.add(host)

    def mend(self, host: str) -> None:
        _ip("-n", self.switch, "link", "set", self._ports[host], "up")
        self.cut_hosts.discard(host)

    def close(self) -> None:
        """Delete every namespace made (their veths and the bridge go with them)."""
        for ns in reversed(self._made):
            _delete(ns)
        self._made = []

    def leftovers(self) -> List[str]:
        return [ns for ns in _namespaces() if ns.startswith(self.tag)]
