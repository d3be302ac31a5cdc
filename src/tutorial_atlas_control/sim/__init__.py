"""The simulation: the MuJoCo model and its URDF, the controller law, the simulator. No ROS.

The controller law comes in two implementations, numpy and compiled.
"""
