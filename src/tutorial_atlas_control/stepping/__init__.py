"""The simulator node's stepping loop without ROS: what is due, pacing, commands, divergence.

schedule: when each message is due and which time it carries (shared with offline runs);
pacing: when to send and how long to wait against wall time; synchronization: the lockstep
window; loop: the loop itself, which node/sim_node.py wraps in rospy publishers,
subscribers and services. No rospy.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'loop': ['LINKS_TF_RATE_HZ', 'ON_DEMAND_MESSAGES', 'ResetControlsRequest', 'SteppingLoop'],
    'pacing': ['Pacer'],
    'schedule': ['step_stamp', 'steps_between'],
    'synchronization': ['DelayBudgets', 'SynchronizationWindow'],
})
