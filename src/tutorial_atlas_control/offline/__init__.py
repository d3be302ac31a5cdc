"""Runs without ROS: the offline trajectory player and the replay of a recorded run."""
