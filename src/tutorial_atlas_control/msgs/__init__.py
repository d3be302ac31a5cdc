"""ROS 1 wire layouts: the JointCommands schema and decoding, pre-serialized messages.

And their filling. No rospy.
"""
