"""Units of standard ROS message fields (REP 103 and the messages' own comments).

A unit given to a field that is itself a message applies to every number below it
(geometry_msgs/Twist `linear` makes linear.x, .y, .z speeds); a deeper entry overrides it.
Containers need no entry: nav_msgs/Odometry's pose.pose.position is metres because
geometry_msgs/Pose says so. Fields absent here have no known dimension.
"""
from __future__ import annotations

import xml.etree.ElementTree as ElementTree
from typing import Dict

from .units import (CURRENT, DIMENSIONLESS, GEO_DEGREE, LENGTH, PRESSURE, SPEED, TEMPERATURE,
                    TIME, VOLTAGE, Dimension, dim)

ANGLE = dim(rad=1)
ANGULAR_SPEED = dim(rad=1, s=-1)
ACCELERATION = dim(m=1, s=-2)
ANGULAR_ACCELERATION = dim(rad=1, s=-2)

# message type -> {field path relative to it (dotted, no indices) -> dimension}
STANDARD_UNITS: Dict[str, Dict[str, Dimension]] = {
    "geometry_msgs/Twist": {"linear": SPEED, "angular": ANGULAR_SPEED},
    "geometry_msgs/Accel": {"linear": ACCELERATION, "angular": ANGULAR_ACCELERATION},
    "geometry_msgs/Pose": {"position": LENGTH, "orientation": DIMENSIONLESS},
    "geometry_msgs/Pose2D": {"x": LENGTH, "y": LENGTH, "theta": ANGLE},
    "geometry_msgs/Transform": {"translation": LENGTH, "rotation": DIMENSIONLESS},
    "geometry_msgs/Quaternion": {"x": DIMENSIONLESS, "y": DIMENSIONLESS, "z": DIMENSIONLESS, "w": DIMENSIONLESS},
    "sensor_msgs/LaserScan": {"angle_min": ANGLE, "angle_max": ANGLE, "angle_increment": ANGLE,
                              "time_increment": TIME, "scan_time": TIME, "range_min": LENGTH,
                              "range_max": LENGTH, "ranges": LENGTH},
    "sensor_msgs/Range": {"field_of_view": ANGLE, "min_range": LENGTH, "max_range": LENGTH, "range": LENGTH},
    "sensor_msgs/Imu": {"angular_velocity": ANGULAR_SPEED, "linear_acceleration": ACCELERATION},
    "sensor_msgs/NavSatFix": {"latitude": GEO_DEGREE, "longitude": GEO_DEGREE, "altitude": LENGTH,
                              "position_covariance": dim(m=2)},
    "sensor_msgs/BatteryState": {"voltage": VOLTAGE, "current": CURRENT, "temperature": TEMPERATURE,
                                 "percentage": DIMENSIONLESS, "cell_voltage": VOLTAGE,
                                 "cell_temperature": TEMPERATURE},
    "sensor_msgs/Temperature": {"temperature": TEMPERATURE},
    "sensor_msgs/FluidPressure": {"fluid_pressure": PRESSURE},
    "sensor_msgs/RelativeHumidity": {"relative_humidity": DIMENSIONLESS},
    "nav_msgs/MapMetaData": {"resolution": LENGTH},
}

# JointState position/velocity/effort by the kind of every joint it names (URDF joint types).
JOINT_UNITS: Dict[str, Dict[str, Dimension]] = {
    "revolute": {"position": ANGLE, "velocity": ANGULAR_SPEED},
    "continuous": {"position": ANGLE, "velocity": ANGULAR_SPEED},
    "prismatic": {"position": LENGTH, "velocity": SPEED},
}


def joint_state_units(kinds: Dict[str, str]) -> Dict[str, Dimension]:
    """Units of a JointState topic whose joints are all of one family (all rotating, or all
    sliding); {} when they mix, are unknown, or fixed."""
    families = {"revolute": "rot", "continuous": "rot", "prismatic": "slide"}
    found = {families.get(k) for k in kinds.values()}
    if not kinds or len(found) != 1 or None in found:
        return {}
    return dict(JOINT_UNITS[next(iter(kinds.values()))])


def urdf_joint_kinds(text: str) -> Dict[str, str]:
    """URDF joint name -> joint type (fixed joints left out); ValueError for text that is not a URDF."""
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError as exc:
        raise ValueError(f"not valid XML: {exc}") from None
    if root.tag != "robot":
        raise ValueError(f"not a URDF: the top element is <{root.tag}>, not <robot>")
    return {j.get("name", ""): j.get("type", "") for j in root.iter("joint") if j.get("type") != "fixed"}
