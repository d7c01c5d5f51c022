"""Pure action logic (no ROS): arbitration of a shared topic by priority, velocity clamping."""
