"""The simulator node's machinery: the node, its transport, the master and recorder
watches, the viewer link. Imports rospy.

The other programs' ROS sides live with their concern, in modules named *_node.py.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'own_clock': ['follow_own_clock'],
    'sim_node': ['NODE_NAME', 'build_node'],
    'single_instance': ['refuse_if_running'],
    'transport': ['WireBatch', 'subscriber_names'],
})
