"""The tutorial end to end, headless, in one command (run_demo.py): demo_node.py.

ROS side only (demo_node.py imports rospy once a launch runs): import it by its module.
"""

__all__: list[str] = []
