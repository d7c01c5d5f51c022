"""Which master the latch state file belongs to: a host of ROS_MASTER_URI is this machine's or
another's (actions/latches.py names the file from it; docs/failure-modes.md)."""
from __future__ import annotations

import ipaddress
import socket


def is_local(host: str) -> bool:
    """Whether `host` (a name or an address) is this machine: a loopback address, this machine's
    name, or an address one of its interfaces holds (a socket can bind to it)."""
    host = host.strip("[]").rstrip(".").lower()
    if host in ("", "localhost", socket.gethostname().lower()):
        return True
    try:
        infos = socket.getaddrinfo(host, None, proto=socket.IPPROTO_TCP)
    except (OSError, UnicodeError):
        return False  # not resolvable here: another machine's name
    for family, _, _, _, addr in infos:
        try:
            if ipaddress.ip_address(addr[0].split("%")[0]).is_loopback:
                return True
            with socket.socket(family, socket.SOCK_DGRAM) as sock:
                sock.bind((addr[0], 0) if family == socket.AF_INET else addr[:1] + (0,) + tuple(addr[2:]))
            return True
        except (OSError, ValueError):
            continue
    return False
