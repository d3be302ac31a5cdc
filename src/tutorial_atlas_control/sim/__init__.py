"""The simulation: the MuJoCo model and its URDF, the controller law (numpy and compiled), the simulator. No ROS."""
