"""A go-to-goal driver (node /controller), standing in for the robot's planner.

Steers a base to a goal point from the odometry (so it reacts to the robot's actual motion,
and fights injected faults as the paper's controller did). ~robot kobuki publishes /cmd_vel
(Twist); ~robot frobit publishes /wheel_left/cmd and /wheel_right/cmd (Float64).
Faults on /sim/fault: {"goal": [x, y]} moves the goal; {"cpu_hog": seconds} runs a CPU-bound
loop in this node for that long (logged as cpu_hog_start).
"""
from __future__ import annotations

import hashlib
import threading
import time

import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from std_msgs.msg import Float64

from .kinematics import DiffDrive, go_to_goal
from .common import loop, on_fault, yaw_of
from .eventlog import EventLog


def main() -> None:
    rospy.init_node("controller")
    robot = rospy.get_param("~robot", "kobuki")
    log = EventLog(rospy.get_param("~events_file", None))
    goal = [float(rospy.get_param("~goal_x", 2.5)), float(rospy.get_param("~goal_y", 1.0))]
    v_max, w_max = float(rospy.get_param("~v_max", 0.3)), float(rospy.get_param("~w_max", 1.0))
    pose = {"x": 0.0, "y": 0.0, "yaw": 0.0, "seen": False}

    def odom(msg: Odometry) -> None:
        pose.update(x=msg.pose.pose.position.x, y=msg.pose.pose.position.y, yaw=yaw_of(msg), seen=True)

    def hog(seconds: float, end: float) -> None:
        """A CPU-bound loop in native code (hashing releases the GIL), as a stuck computation
        in a real controller would be: it takes a core, whatever the node's other threads do."""
        block = b"\0" * (1 << 20)
        while time.monotonic() < end:
            hashlib.sha256(block).digest()

    def fault(f: dict) -> None:
        if "goal" in f:
            goal[:] = f["goal"]
            log.log("fault_applied", goal=f["goal"])
        if "cpu_hog" in f:
            seconds = float(f["cpu_hog"])
            log.log("cpu_hog_start", seconds=seconds, threads=int(f.get("threads", 1)))
            for _ in range(int(f.get("threads", 1))):
                threading.Thread(target=hog, args=(seconds, time.monotonic() + seconds), daemon=True).start()

    on_fault(fault)
    rospy.Subscriber("/odom", Odometry, odom, tcp_nodelay=True)
    if robot == "kobuki":
        pub = rospy.Publisher("/cmd_vel", Twist, queue_size=10, tcp_nodelay=True)
    else:
        left = rospy.Publisher("/wheel_left/cmd", Float64, queue_size=10, tcp_nodelay=True)
        right = rospy.Publisher("/wheel_right/cmd", Float64, queue_size=10, tcp_nodelay=True)
        wheels = DiffDrive(track=0.3)
    def step() -> None:
        v, w = go_to_goal(pose["x"], pose["y"], pose["yaw"], goal[0], goal[1], v_max, w_max) if pose["seen"] \
            else (0.0, 0.0)
        if robot == "kobuki":
            t = Twist()
            t.linear.x, t.angular.z = v, w
            pub.publish(t)
        else:
            lw, rw = wheels.wheels_for(v, w)
            left.publish(Float64(lw))
            right.publish(Float64(rw))

    loop(20.0, step)


if __name__ == "__main__":
    main()
