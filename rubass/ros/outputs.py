"""The monitor's own publications: /diagnostics, ~events (JSON) and ~heartbeat."""
from __future__ import annotations

import json
import socket
from typing import Any, Dict, List

import rospy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from std_msgs.msg import Header, String

from ..actions.status import Entry


class Outputs:
    def __init__(self) -> None:
        self.events = rospy.Publisher("~events", String, queue_size=1000, tcp_nodelay=True)
        self.heartbeat = rospy.Publisher("~heartbeat", Header, queue_size=1, tcp_nodelay=True)
        self.diagnostics = rospy.Publisher("/diagnostics", DiagnosticArray, queue_size=5)
        self.node_samples = rospy.Publisher("~node_samples", String, queue_size=100, tcp_nodelay=True)
        self._seq = 0
        self._hw = socket.gethostname()
        # two monitors on one robot must not publish the same status names (an aggregator would merge
        # them, one's OK masking the other's ERROR): a node other than /rubass says its name
        node = rospy.get_name()
        self._prefix = "rubass:" if node == "/rubass" else f"rubass {node}:"

    def beat(self, now: float) -> None:
        """One heartbeat; published from the engine's thread, so it stops if the engine stalls."""
        self._seq += 1
        self.heartbeat.publish(Header(seq=self._seq, stamp=rospy.Time.from_sec(now), frame_id="rubass"))

    def event(self, record: Dict[str, Any]) -> None:
        self.events.publish(String(data=json.dumps(record, sort_keys=True)))

    def node_sample(self, node: str, now: float, alive: Any, cpu: Any, memory: Any) -> None:
        """A node sample as JSON, so that recordings carry them (rubass replay uses them)."""
        known = lambda v: v if isinstance(v, (bool, float)) else None  # noqa: E731
        self.node_samples.publish(String(data=json.dumps(
            {"node": node, "time": now, "alive": known(alive), "cpu": known(cpu), "memory": known(memory)})))

    def status(self, entries: List[Entry], now: float) -> None:
        arr = DiagnosticArray()
        arr.header.stamp = rospy.Time.from_sec(now)
        for e in entries:
            name = e.name if not e.name.startswith("rubass:") else self._prefix + e.name[len("rubass:"):]
            arr.status.append(DiagnosticStatus(level=e.level, name=name,
                                               message=e.message, hardware_id=self._hw,
                                               values=[KeyValue(key=k, value=v) for k, v in e.values]))
        self.diagnostics.publish(arr)

    def close(self) -> None:
        for pub in (self.events, self.heartbeat, self.diagnostics, self.node_samples):
            pub.unregister()
