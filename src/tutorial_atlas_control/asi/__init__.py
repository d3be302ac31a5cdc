"""The open AtlasSimInterface, ROS-free: DRCSim 2.7's behaviour library contract (ASI.md)
over the simulator and the balance. errors: AsiInputError, an input its clients cannot
take; behaviors: its numbers and which control mode runs each behaviour; library: what the
interface asks of a behaviour beyond Stand (Walk, Step, a user's own); user_behaviour: a
user's class named by a launch argument, loaded; session: requests taken or refused and the
feedback status; walk_params: a WALK's steps and walk_feedback; interface: one simulator's
requests applied and its states built; walk_client: what a walking client does with each
state; walk_demo: DRCSim's actionlib server's decisions; teleop: the keyboard teleop's keys
and steps; mode_switching: DRCSim's mode-switching demo as cues of messages.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'behaviors': ['AsiError', 'Behavior', 'Status'],
    'errors': ['AsiInputError'],
    'interface': ['AtlasSimInterface'],
    'library': ['BehaviourBase', 'Handover', 'LibraryBehaviour', 'on_ground'],
    'mode_switching': ['AFTER_LAST_S', 'CUES', 'KP_VELOCITY', 'cue_messages'],
    'teleop': ['Settings', 'ego_steps', 'key_action'],
    'user_behaviour': ['UserBehaviourError', 'load_user_behaviour'],
    'walk_client': ['Outcome', 'WalkClient', 'refusal_hint'],
    'walk_params': ['step_data_of', 'walk_command'],
    'walk_demo': ['Decision', 'WalkDemoServer', 'yaw_of_quaternion'],
})
