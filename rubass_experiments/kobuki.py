"""A Kobuki-like simulated base (node /mobile_base).

Integrates its velocity command at 50 Hz (differential drive, wheel lag) and publishes
/odom (nav_msgs/Odometry) and /mobile_base/sensors/joint_states (wheel speeds). Commands come
on /mobile_base/commands/velocity and, with priority, on /mobile_base/commands/safety_velocity
(as yocs_cmd_vel_mux: an input counts for 0.5 s after its last message), so the monitor's zero
Twist stops it whatever the controller says.

Params: ~events_file (where to log stop_received and boundary), ~x_min, ~x_max, ~y_max (the
allowed area, for the boundary event only).
"""
from __future__ import annotations

import time

import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import JointState

from .kinematics import DiffDrive
from .common import as_hardware, loop, odometry
from .eventlog import EventLog

MUX_TIMEOUT = 0.5


def main() -> None:
    as_hardware()
    rospy.init_node("mobile_base")
    log = EventLog(rospy.get_param("~events_file", None))
    area = (rospy.get_param("~x_min", -1.0), rospy.get_param("~x_max", 3.0), rospy.get_param("~y_max", 2.0))
    base = DiffDrive(track=0.23)
    cmd = {"normal": (Twist(), 0.0), "safety": (Twist(), 0.0)}

    def normal(msg: Twist) -> None:
        cmd["normal"] = (msg, time.monotonic())

    def safety(msg: Twist) -> None:
        log.log("stop_received", once=True, source="safety_velocity")
        cmd["safety"] = (msg, time.monotonic())

    rospy.Subscriber("/mobile_base/commands/velocity", Twist, normal, tcp_nodelay=True)
    rospy.Subscriber("/mobile_base/commands/safety_velocity", Twist, safety, tcp_nodelay=True)
    odom = rospy.Publisher("/odom", type(odometry(base, rospy.Time())), queue_size=10, tcp_nodelay=True)
    joints = rospy.Publisher("/mobile_base/sensors/joint_states", JointState, queue_size=10, tcp_nodelay=True)
    dt = 0.02

    def step() -> None:
        now = time.monotonic()
        twist = Twist()
        for source in ("safety", "normal"):
            msg, at = cmd[source]
            if now - at < MUX_TIMEOUT:
                twist = msg
                break
        base.step(*base.wheels_for(twist.linear.x, twist.angular.z), dt)
        if not (area[0] <= base.x <= area[1] and abs(base.y) <= area[2]):
            log.log("boundary", once=True, x=base.x, y=base.y)
        stamp = rospy.Time.now()
        odom.publish(odometry(base, stamp))
        js = JointState(name=["wheel_left", "wheel_right"], velocity=[base.left, base.right])
        js.header.stamp = stamp
        joints.publish(js)

    loop(1.0 / dt, step)


if __name__ == "__main__":
    main()
