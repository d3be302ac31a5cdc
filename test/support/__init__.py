"""Helpers shared by the test directories: imported as `support` (pytest.ini puts test/ on
the path; bench/ adds it to its own). The benchmark uses two of them: fake_rospy, the node
on a fake rospy, which bench/node_loop.py times and the unit tests drive, and
synthetic_bags, the run bag bench/offline.py reads. Beside them: statics, the gravity
stiffness of a stance joint (test_statics.py)."""
