"""Everything that imports rospy.

The simulator node, its transport, viewer link, state publisher, the traj_yaml node and the
demo driver.
"""
