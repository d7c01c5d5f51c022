"""The monitor process's one arbiter (rubass/actions/arbitration.py), keyed by resolved topic
names: publish and limit actions take a seat on their topic when they are set up."""
from __future__ import annotations

import rospy

from ...actions.arbitration import Arbiter, Handover, Seat

ARBITER = Arbiter()


def take_seat(topic: str, name: str, priority: int, on_handover: Handover) -> Seat:
    return ARBITER.seat(rospy.resolve_name(topic), name, priority, on_handover)
