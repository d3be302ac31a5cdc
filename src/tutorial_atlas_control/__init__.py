"""tutorial_atlas_control: the DRCSim Atlas joint-trajectory tutorial on ROS 1 and MuJoCo.

Pure logic (model loading, controller law, trajectory files, bag metrics) lives in
this package so it can be unit-tested without a ROS master; the scripts and the
simulator node are thin ROS glue around it.
"""
