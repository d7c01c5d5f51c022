"""The ROS shell: everything that imports rospy, rosbag, genpy, psutil or pyserial lives here."""
