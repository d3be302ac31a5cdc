"""The tutorial end to end, headless, in one command (run_demo.py): demo_node.py.

ROS side only (demo_node.py imports rospy once a launch runs): import it by its module.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
})
