"""What a rubass agent has discovered, kept across its own restarts.

rospy nodes register with the master once, at start: after a master restart the new master
knows only the nodes started since, so an agent restarted then would never learn of the nodes
that kept running, and their cpu() and memory() would stay unknown. The agent therefore keeps
the nodes of its host it has discovered (node name -> XML-RPC URI) in a small JSON file,
$ROS_HOME/rubass/agent_<host>.json, reloads it at start, and keeps an entry only while the node
at that URI answers getName with that name, or, for a C++ node (roscpp has no getName), getPid
(`check`). No rospy: the file and the question only.
"""
from __future__ import annotations

import json
import os
import re
import socket
import xmlrpc.client
from typing import Dict, Optional

from . import rpc

VERSION = 1


def cache_path(ros_home: Optional[str], host: str) -> str:
    """$ROS_HOME/rubass/agent_<host>.json (ROS_HOME defaults to ~/.ros, as ROS's own)."""
    home = ros_home or os.path.join(os.path.expanduser("~"), ".ros")
    return os.path.join(home, "rubass", "agent_" + (re.sub(r"[^A-Za-z0-9_.-]", "_", host) or "host") + ".json")


def load(path: str) -> Dict[str, str]:
    """The cached nodes, {} if there is no file; ValueError saying why a file cannot be used."""
    try:
        with open(path) as fh:
            data = json.load(fh)
    except FileNotFoundError:
        return {}
    except (OSError, ValueError) as exc:
        raise ValueError(f"cannot read {path}: {exc}") from None
    nodes = data.get("nodes") if isinstance(data, dict) else None
    if not isinstance(nodes, dict):
        raise ValueError(f"{path} is not an agent's node cache (no 'nodes' object)")
    return {str(k): str(v) for k, v in nodes.items() if isinstance(v, str) and v.startswith("http://")}


def save(path: str, nodes: Dict[str, str]) -> None:
    """Write the cache atomically (a crash leaves the old file or the new one); OSError if it cannot."""
    os.makedirs(os.path.dirname(path), exist_ok=True)
    tmp = f"{path}.{os.getpid()}.tmp"
    with open(tmp, "w") as fh:
        json.dump({"version": VERSION, "nodes": dict(sorted(nodes.items()))}, fh, indent=1)
    os.replace(tmp, path)


def check(name: str, uri: str, caller_id: str, timeout: float) -> Optional[bool]:
    """Whether the node at `uri` is `name`: True if it answers getName with it, False if something
    else answers there or nothing does (refused: the node is gone), None if no answer came within
    `timeout` (a hung node: neither kept as known nor forgotten). A C++ node (roscpp) has no getName:
    one that answers getPid there is taken to be it (its name cannot be asked)."""
    caller = rpc.Caller(uri, timeout, keep_alive=False)
    try:
        code, _, answer = caller.call("getName", caller_id)
        return code == 1 and answer == name
    except xmlrpc.client.Fault:  # a server that does not know getName: roscpp's slave API
        pass
    except socket.timeout:
        return None
    except (OSError, xmlrpc.client.Error, ValueError):
        return False
    try:
        code, _, _ = caller.call("getPid", caller_id)
    except socket.timeout:
        return None
    except (OSError, xmlrpc.client.Error, ValueError):
        return False
    return code == 1
