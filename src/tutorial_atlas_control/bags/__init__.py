"""Recorded runs: bag records, reading, analysis, comparison, reports, videos, run logs, synthetic bags. No ROS."""
