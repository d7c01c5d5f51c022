"""Topic names of a spec resolved as the live monitor resolves them, for replay, rule tests and
the system model.

The monitor subscribes once per resolved name, and every spelling of a topic in the spec
(`/cmd_vel`, `cmd_vel`, `~x`) gets every message (docs/monitor.md). Without a master there is
no node to ask, so names resolve as they do for a monitor with its default name, `rubass`, in
the root namespace: relative names from `/`, private `~x` as `/rubass/x`.
"""
from __future__ import annotations

from typing import Dict, Iterable, List

MONITOR_NODE = "/rubass"  # the monitor's default node name (launch/monitor.launch)


def resolve(name: str, node: str = MONITOR_NODE) -> str:
    """The global name of a topic (ROS rules, as rospy.resolve_name in node `node` at the root)."""
    parts = [p for p in name.lstrip("~").split("/") if p]
    if name.startswith("~"):
        parts = [p for p in node.split("/") if p] + parts
    return "/" + "/".join(parts)


def spellings(names: Iterable[str], node: str = MONITOR_NODE) -> Dict[str, List[str]]:
    """Resolved name -> the spec's spellings of it, sorted: one entry per topic on the wire."""
    out: Dict[str, List[str]] = {}
    for name in sorted(names):
        out.setdefault(resolve(name, node), []).append(name)
    return out
