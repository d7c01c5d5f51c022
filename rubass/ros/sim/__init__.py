"""The simulated robots, the fault injector and the experiment runner (ROS nodes)."""
