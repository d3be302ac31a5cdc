"""The simulator node's stepping loop without ROS, one module per concern.

loop: the loop itself (SteppingLoop), which node/sim_node.py wraps in rospy publishers,
subscribers and services; tick: one step in its order (inputs, physics, state, the
interface's end of step), the loop's and offline runs'; controller: the StepController
protocol a controller plugs in by; inbox: the commands waiting for the next step and their
merge; publication: what is sent each step, as topics.INTERFACE declares it; sync_gate and
synchronization: DRCSim's synchronization window; controls: resets, pause, modes, cheats;
course_scoring: the VRC course's scoring fed after each step (score.log, /vrc_score);
watch: the headless log lines; divergence: recovery from a diverged physics; outputs: where
the loop writes; schedule: when each message is due and which time it carries (shared with
offline runs); pacing: when to send and how long to wait against wall time. No rospy.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'controller': ['StepController'],
    'controls': ['ResetControlsRequest'],
    'course_scoring': ['CourseScoring'],
    'loop': ['LoopSettings', 'SteppingLoop'],
    'outputs': ['LoopLog', 'LoopOutputs', 'Outbox'],
    'pacing': ['Pacer'],
    'publication': ['LINKS_TF_RATE_HZ', 'StepPublisher', 'default_rates_hz'],
    'schedule': ['step_stamp', 'steps_between'],
    'synchronization': ['DelayBudgets', 'SynchronizationWindow'],
    'tick': ['Tick'],
})
