"""The tutorial end to end, headless, in one command (run_demo.py): demo_node.py; and
Atlas walking the same way: walk_demo_node.py.

ROS side only (both import rospy once a launch runs): import them by their modules.
"""

__all__: list[str] = []
