"""Helpers shared by the test directories: imported as `support` (pytest.ini puts test/ on
the path). What the benchmark needs too lives in the package (processes, synthetic_bags)
or in tools/ (flood_commands.py), except fake_rospy, the node on a fake rospy, which
bench/node_loop.py times and the unit tests drive."""
