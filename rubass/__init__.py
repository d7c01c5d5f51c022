"""rubass: a runtime safety monitor for ROS 1 robots, driven by RuBaSS specs."""
__version__ = "0.1.0"
