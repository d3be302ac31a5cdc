"""The simulator node's stepping loop without ROS: what is due, pacing, commands, divergence.

schedule: when each message is due and which time it carries (shared with offline runs);
pacing: when to send and how long to wait against wall time; loop: the loop itself, which
node/sim_node.py wraps in rospy publishers, subscribers and services. No rospy.
"""
