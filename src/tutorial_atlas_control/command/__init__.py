"""The command the controller law reads: JointCommands' arrays as numpy, checked, merged.

Below msgs/ (whose decoders produce commands from the wire) and sim/ (whose law applies
them). No ROS.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'arrays': ['ALL_JOINTS', 'FIELD_NAMES', 'K_EFFORT_ROW', 'LAW_FIELDS', 'MAX_MAGNITUDE',
               'CommandError', 'CommandUpdate', 'JointCommandArrays', 'check_values',
               'checked_update', 'command_update', 'joint_indices', 'merge_command'],
})
