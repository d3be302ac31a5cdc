"""Recorded runs: bag records, reading, analysis, comparison, reports, videos, run logs.

Also synthetic bags for the tests. No ROS.
"""
