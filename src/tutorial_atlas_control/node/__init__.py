"""Everything that imports rospy: the simulator node, its transport, viewer link, state publisher, the traj_yaml node and the demo driver."""
