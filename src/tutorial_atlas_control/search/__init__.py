"""Sweeps of many offline runs on Dask, and the search over them (issue 27). No ROS."""
