"""What the simulated nodes share: reading faults, publishing odometry."""
from __future__ import annotations

import json
import math
from typing import Any, Callable, Dict

import rospy
from nav_msgs.msg import Odometry
from std_msgs.msg import String

from .kinematics import DiffDrive

FAULT_TOPIC = "/sim/fault"


def on_fault(handler: Callable[[Dict[str, Any]], None]) -> rospy.Subscriber:
    """Subscribe to the runner's fault commands (JSON in std_msgs/String)."""
    return rospy.Subscriber(FAULT_TOPIC, String, lambda m: handler(json.loads(m.data)), tcp_nodelay=True)


def odometry(base: DiffDrive, stamp: rospy.Time) -> Odometry:
    msg = Odometry()
    msg.header.stamp = stamp
    msg.header.frame_id = "odom"
    msg.child_frame_id = "base_link"
    msg.pose.pose.position.x, msg.pose.pose.position.y = base.x, base.y
    msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = math.sin(base.yaw / 2), math.cos(base.yaw / 2)
    v, w = base.body()
    msg.twist.twist.linear.x, msg.twist.twist.angular.z = v, w
    return msg


def yaw_of(msg: Odometry) -> float:
    q = msg.pose.pose.orientation
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def freeze_heap() -> None:
    """Keep full garbage collections out of a simulated node's timing. A rospy node holds ~43,000
    objects; a full collection of them took 11-14 ms here and held the GIL, so a stop arriving then
    reached the simulated base that much later and counted in the monitor's (b), while a real base
    driver is C++. The set-up is frozen out of the collector's scans, as the monitor's is."""
    from rubass.ros.gcfreeze import freeze_heap as freeze

    freeze()


def as_hardware() -> None:
    """Run a simulated base or safety board at the monitor's priority (nice -10, as root; else as
    started). It stands for a motor controller or a microcontroller, which do not wait for a core of
    the robot computer: at nice 0 beside the monitor at -10, the stop's way from the monitor to the
    simulated board once took 10 ms on the CI machine (M_L+E_R), which (b) counted as the monitor's.
    Called first in main(), so that rospy's threads inherit it."""
    from rubass.ros.priority import set_nice

    set_nice(-10)


def loop(hz: float, step: Callable[[], None]) -> None:
    """Call step() hz times a second until ROS shuts down (the set-up done so far frozen first)."""
    freeze_heap()
    rate = rospy.Rate(hz)
    while not rospy.is_shutdown():
        step()
        try:
            rate.sleep()
        except rospy.ROSInterruptException:
            break
