"""ROS 1 wire layouts: the JointCommands schema and decoding, pre-serialized messages and their filling. No rospy."""
