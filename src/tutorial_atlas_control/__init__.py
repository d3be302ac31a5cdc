"""tutorial_atlas_control: the DRCSim Atlas joint-trajectory tutorial on ROS 1 and MuJoCo.

Pure logic (model loading, controller law, trajectory files, bag metrics) lives in
this package so it can be unit-tested without a ROS master; the scripts and the
simulator node are thin ROS glue around it.

The layers, lowest first (test_layers.py keeps the order): the facts (top-level modules:
joints, units, topics, errors, resources, processes, exports) -> command (what the law
reads) -> native (the compiled library) -> msgs (wire formats), plotting -> sim (the
simulation, and the messages filled from it) -> stepping (the live loop), trajectories ->
bags -> offline, demo -> search -> node (the simulator node) -> cli. rospy only in node/,
cli/ and modules named *_node.py.
"""
