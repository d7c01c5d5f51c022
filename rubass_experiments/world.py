"""The Kobuki-like base's surroundings (node /world): one round obstacle, seen by a simulated
laser and felt by a bumper, for the `limit` demo rows of `rubass experiments`.

Publishes /scan (sensor_msgs/LaserScan, 360 beams from -180° to 179°, index 180 straight
ahead, +inf where nothing is hit, 25 Hz) and /mobile_base/sensors/bumper (std_msgs/UInt8,
1 while the base touches the obstacle, 50 Hz), from /odom. The base has no collision physics:
the bumper only reports contact. Listens beside the base to /mobile_base/commands/safety_velocity.

Logs (~events_file): obstacle_near (the first scan whose front sector [150:210] reads less than
~near m), bumper_pressed (first contact), creep_received (the first safety command after
obstacle_near with |linear.x| <= ~creep m/s), escape_received (the first safety command after
bumper_pressed that does not move forward or turn).
Params: ~obstacle_x, ~obstacle_y, ~obstacle_r (m), ~robot_r (m), ~near (m), ~creep (m/s).
"""
from __future__ import annotations

import math
import time
from typing import Dict, Optional

import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from std_msgs.msg import UInt8

from .common import loop, yaw_of
from .eventlog import EventLog

BEAMS = 360
FRONT = slice(150, 210)
RANGE_MAX = 6.0


def ray_to_circle(x: float, y: float, angle: float, cx: float, cy: float, r: float) -> float:
    """Distance along a ray from (x, y) at `angle` to the circle's edge; inf when it misses."""
    dx, dy = math.cos(angle), math.sin(angle)
    fx, fy = x - cx, y - cy
    b = fx * dx + fy * dy
    disc = b * b - (fx * fx + fy * fy - r * r)
    if disc < 0:
        return math.inf
    t = -b - math.sqrt(disc)
    return t if t > 0 else (0.0 if fx * fx + fy * fy <= r * r else math.inf)


def main() -> None:
    rospy.init_node("world")
    log = EventLog(rospy.get_param("~events_file", None))
    ox, oy = float(rospy.get_param("~obstacle_x", 1.5)), float(rospy.get_param("~obstacle_y", -1.0))
    orad, rrad = float(rospy.get_param("~obstacle_r", 0.15)), float(rospy.get_param("~robot_r", 0.18))
    near, creep = float(rospy.get_param("~near", 0.8)), float(rospy.get_param("~creep", 0.1))
    pose: Dict[str, Optional[float]] = {"x": None, "y": None, "yaw": None}
    seen = {"near": False, "bumped": False}

    def odom(msg: Odometry) -> None:
        pose.update(x=msg.pose.pose.position.x, y=msg.pose.pose.position.y, yaw=yaw_of(msg))

    def safety(msg: Twist) -> None:
        if seen["near"] and abs(msg.linear.x) <= creep + 1e-9:
            log.log("creep_received", once=True, linear=msg.linear.x)
        if seen["bumped"] and msg.linear.x <= 1e-9 and abs(msg.angular.z) <= 1e-9:
            log.log("escape_received", once=True, linear=msg.linear.x)

    rospy.Subscriber("/odom", Odometry, odom, tcp_nodelay=True)
    rospy.Subscriber("/mobile_base/commands/safety_velocity", Twist, safety, tcp_nodelay=True)
    scan_pub = rospy.Publisher("/scan", LaserScan, queue_size=10, tcp_nodelay=True)
    bumper_pub = rospy.Publisher("/mobile_base/sensors/bumper", UInt8, queue_size=10, tcp_nodelay=True)
    tick = {"n": 0}

    def scan(x: float, y: float, yaw: float) -> None:
        msg = LaserScan()
        msg.header.stamp, msg.header.frame_id = rospy.Time.now(), "base_scan"
        msg.angle_min, msg.angle_increment = -math.pi, 2 * math.pi / BEAMS
        msg.angle_max = msg.angle_min + (BEAMS - 1) * msg.angle_increment
        msg.scan_time, msg.range_min, msg.range_max = 0.05, 0.05, RANGE_MAX
        msg.ranges = [ray_to_circle(x, y, yaw + msg.angle_min + i * msg.angle_increment, ox, oy, orad)
                      for i in range(BEAMS)]
        msg.ranges = [r if r <= RANGE_MAX else math.inf for r in msg.ranges]
        front = min(msg.ranges[FRONT])
        wall = time.time()
        scan_pub.publish(msg)
        if front < near and not seen["near"]:
            seen["near"] = True
            log.log("obstacle_near", once=True, range=front, wall_published=wall)

    def step() -> None:
        x, y, yaw = pose["x"], pose["y"], pose["yaw"]
        if x is None or y is None or yaw is None:
            return
        touching = math.hypot(x - ox, y - oy) <= orad + rrad
        bumper_pub.publish(UInt8(1 if touching else 0))
        if touching and not seen["bumped"]:
            seen["bumped"] = True
            log.log("bumper_pressed", once=True, x=x, y=y)
        tick["n"] += 1
        if tick["n"] % 2 == 0:  # 50 Hz loop: the laser at 25 Hz
            scan(x, y, yaw)

    loop(50.0, step)


if __name__ == "__main__":
    main()
