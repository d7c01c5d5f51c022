"""Simulated robots and the paper's experiments: the pure parts (kinematics, faults, rows,
statistics). The ROS nodes that use them are in rubass/ros/sim/."""
