"""Trajectory files (lookup, validation, interpolation) and the 50 Hz schedule. No ROS."""
