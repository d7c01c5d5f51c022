"""The fault injector of the Kobuki-like experiments (node /fault_injector), the paper's test node.

Relays the controller's /cmd_vel to /mobile_base/commands/velocity and, after a fault
command ({"drift": "linear" | "angular", "rate": r} on /sim/fault), adds a drift growing by r
per second to that field. Logs fault_applied, and limit_exceeded the first time a relayed
command is over ~max_speed (m/s) or ~max_spin (rad/s).
"""
from __future__ import annotations

import time

import rospy
from geometry_msgs.msg import Twist

from .faults import Drift
from .common import freeze_heap, on_fault
from .eventlog import EventLog


def main() -> None:
    rospy.init_node("fault_injector")
    log = EventLog(rospy.get_param("~events_file", None))
    max_speed, max_spin = float(rospy.get_param("~max_speed", 0.5)), float(rospy.get_param("~max_spin", 1.5708))
    drift = {"linear": Drift(0.0), "angular": Drift(0.0)}
    out = rospy.Publisher("/mobile_base/commands/velocity", Twist, queue_size=10, tcp_nodelay=True)

    def fault(f: dict) -> None:
        if f.get("drift") in drift:
            drift[f["drift"]] = Drift(float(f["rate"]), time.monotonic())
            log.log("fault_applied", drift=f["drift"], rate=f["rate"])

    def relay(msg: Twist) -> None:
        now = time.monotonic()
        msg.linear.x += drift["linear"].amount(now)
        msg.angular.z += drift["angular"].amount(now)
        out.publish(msg)
        if abs(msg.linear.x) > max_speed or abs(msg.angular.z) > max_spin:
            log.log("limit_exceeded", once=True, linear=msg.linear.x, angular=msg.angular.z)

    on_fault(fault)
    rospy.Subscriber("/cmd_vel", Twist, relay, tcp_nodelay=True)
    freeze_heap()
    rospy.spin()


if __name__ == "__main__":
    main()
