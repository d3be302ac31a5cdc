"""The simulation: the MuJoCo model and its URDF, the controller law, the simulator, the
messages filled from its state. No ROS.

The controller law comes in two implementations, numpy and compiled. The ROS side of the
robot description, state_publisher_node.py, is imported by its module.
"""

from tutorial_atlas_control.exports import lazy_exports

__all__, __getattr__, __dir__ = lazy_exports(__name__, {
    'body_forces': ['step_with_body_forces'],
    'camera': ['CAMERA', 'configure_viewer_camera', 'configure_viewer_scene'],
    'controller': ['DEFAULT_GAINS_FILE', 'Gains', 'GainsError', 'LOAD_HINT', 'gains_from_params',
                   'load_gains_yaml'],
    'controller_statistics': ['CommandAgeStatistics', 'DEFAULT_WINDOW_S', 'UPDATE_RATE_PARAM',
                              'WINDOW_PARAM'],
    'copy_plan': ['CopyPlan'],
    'divergence': ['DivergenceCheck', 'PhysicsDivergenceError'],
    'fall': ['FALLING_PELVIS_M', 'FALLING_TILT_RAD', 'FALL_HEIGHT_M', 'GroundUnderFeet',
             'STANDING_PELVIS_M', 'fallen', 'fallen_samples', 'falling', 'standing'],
    'ground': ['Ground', 'GroundError', 'GroundHit', 'ROBOT_ROOT_BODY'],
    'joint_law': ['JointLaw'],
    'joint_trajectory': ['TrajectoryMessage', 'trajectory_input'],
    'law_kernel': ['CompiledLaw', 'LawJoints'],
    'link_transforms': ['LinkTransforms', 'RspSchedule'],
    'mode_commands': ['ControlMode', 'ModeCommands', 'ModeError', 'VALID_MODES', 'parse_mode'],
    'mud': ['MUD_GEOM', 'MudDrag'],
    'model': ['AtlasModel', 'MODEL_PATH', 'ORIGIN_PELVIS_QPOS', 'SOLE_GEOMS', 'SPAWN_HEIGHT_M',
              'body_position_in_pose', 'index_model', 'load_model', 'pelvis_height_m',
              'reset_to_initial'],
    'shared_passes': ['SHARED_PASSES_ENV', 'behaviour_between', 'passes_current',
                      'shares_passes', 'step_behaviour'],
    'sim_config': ['SimConfig', 'SimConfigError', 'parse_sim_config'],
    'sim_messages': ['SimMessages', 'TCPROS_PREFIX_BYTES'],
    'simulator': ['AtlasSimulator', 'DEFAULT_TIME_TO_UNPIN_S'],
    'start_pose': ['home_qpos', 'sole_bottom_corners', 'start_line', 'start_pose',
                   'yaw_quaternion'],
    'startup_pin': ['StartupPin'],
    'urdf': ['UrdfError', 'matching_urdf', 'read_joints'],
    'vrc': ['DEFAULT_STARTUP_MODE', 'InputError', 'InputEvent', 'InputNote', 'ModeInput',
            'STAND_POSE_RAD', 'STARTUP_MODES', 'SimInput', 'TrajectoryInput', 'VrcMode',
            'cmd_vel_input', 'describe_input', 'input_notes', 'parse_vrc_mode', 'pose_input',
            'wrench_input'],
})
