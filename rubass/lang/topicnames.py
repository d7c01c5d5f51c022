"""Topic names of a spec resolved as the live monitor resolves them, for replay, rule tests and
the system model.

The monitor subscribes once per resolved name, and every spelling of a topic in the spec
(`/cmd_vel`, `cmd_vel`, `~x`) gets every message (docs/monitor.md). Without a master there is
no node to ask, so names resolve as they do for a monitor with its default name, `rubass`, in
the namespace `rosrun` would start it in: `$ROS_NAMESPACE` when set (as rospy reads it), else the
root: relative names from there, private `~x` as `/NS/rubass/x`.
"""
from __future__ import annotations

import os
from typing import Dict, Iterable, List, Optional

MONITOR_NAME = "rubass"  # the monitor's default node name (launch/monitor.launch)


def monitor_node() -> str:
    """The monitor's full node name offline: `/rubass`, or `/NS/rubass` with ROS_NAMESPACE=NS."""
    ns = [p for p in os.environ.get("ROS_NAMESPACE", "").split("/") if p]
    return "/" + "/".join(ns + [MONITOR_NAME])


def resolve(name: str, node: Optional[str] = None) -> str:
    """The global name of a topic (ROS rules, as rospy.resolve_name in node `node`, by default
    monitor_node()): absolute as written, relative in the node's namespace, `~x` under the node."""
    node = node or monitor_node()
    parts = [p for p in name.lstrip("~").split("/") if p]
    if name.startswith("~"):
        parts = [p for p in node.split("/") if p] + parts
    elif not name.startswith("/"):
        parts = [p for p in node.split("/") if p][:-1] + parts
    return "/" + "/".join(parts)


def spellings(names: Iterable[str], node: Optional[str] = None) -> Dict[str, List[str]]:
    """Resolved name -> the spec's spellings of it, sorted: one entry per topic on the wire."""
    node = node or monitor_node()
    out: Dict[str, List[str]] = {}
    for name in sorted(names):
        out.setdefault(resolve(name, node), []).append(name)
    return out
