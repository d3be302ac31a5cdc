"""ROS 1 wire formats: schemas, decoding, checks and pre-serialized messages. No rospy.

What fills the messages from the simulator each step is sim/sim_messages.py.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'atlas_command': ['AtlasCommandDecoder', 'AtlasUpdate', 'decode_atlas_command', 'decode_test',
                      'encode_atlas_command'],
    'atlas_sim_interface': ['STEP_QUEUE_LENGTH', 'AsiCommand', 'ManipulateParams', 'StepData',
                            'decode_asi_command', 'encode_asi_command'],
    'atlas_sim_interface_state': ['AsiState', 'BehaviorFeedback', 'ManipulateFeedback',
                                  'StepFeedback', 'WalkFeedback', 'encode_asi_state'],
    'joint_commands': ['CommandDecoder'],
    'ros1_fields': ['FieldCursor', 'parse_names_arrays'],
    'udpros': ['HEADER', 'HEADER_SIZE', 'OP_DATA0', 'OP_DATAN', 'PROTOCOL', 'UdprosError',
               'framed_messages', 'message_blocks', 'next_message_id', 'parse_request', 'reply'],
    'wire': ['AtlasStateWire', 'ControllerStatisticsWire', 'ForceTorqueSensorsWire', 'ImuWire',
             'JointCommandsWire', 'JointStateWire', 'LaserScanWire', 'OdometryWire',
             'PositionsWire', 'StampedWire', 'TransformWire', 'TransformsWire', 'WRENCH_FLOATS',
             'WrenchStampedWire', 'clock_bytes'],
})
