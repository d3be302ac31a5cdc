"""The ROS names the simulator, the tutorial script, the recorder and the bag tools share.

DRCSim's names, kept verbatim so that DRCSim-era clients and `rostopic` habits work.
"""

from __future__ import annotations

CLOCK = '/clock'
JOINT_STATES = '/atlas/joint_states'
JOINT_COMMANDS = '/atlas/joint_commands'
CONTROL_MODE = '/atlas/control_mode'
GROUND_TRUTH_ODOM = '/ground_truth_odom'
IMU = '/atlas/imu'
L_FOOT_CONTACT = '/atlas/l_foot_contact'
R_FOOT_CONTACT = '/atlas/r_foot_contact'
#: DRCSim's atlas_msgs/AtlasState (joints, active gains, k_effort, IMU, four wrenches) and
#: atlas_msgs/ForceTorqueSensors; the ankle contact wrenches of its debug topics.
ATLAS_STATE = '/atlas/atlas_state'
FORCE_TORQUE_SENSORS = '/atlas/force_torque_sensors'
DEBUG_L_FOOT_CONTACT = '/atlas/debug/l_foot_contact'
DEBUG_R_FOOT_CONTACT = '/atlas/debug/r_foot_contact'
#: atlas_msgs/ControllerStatistics: the age of the command the robot obeys (DRCSim's).
CONTROLLER_STATISTICS = '/atlas/controller_statistics'
#: Latched JSON (timestep, time_to_unpin, model file and sha1, last reset): what replay needs.
SIM_CONFIG = '/atlas/sim_config'
#: Latched std_msgs/String: the simulator's control mode now (not recorded: the bag has the
#: /atlas/control_mode requests). traj_yaml.py reads it to warn when it is not User.
CURRENT_CONTROL_MODE = '/atlas/current_control_mode'
#: The tutorial's command switching the simulator to User mode (the README's form).
SWITCH_TO_USER = 'rostopic pub /atlas/control_mode std_msgs/String -- "User"'
ROSOUT = '/rosout'
#: VRCPlugin's inputs (DRCSim's "cheats"): std_msgs/String, geometry_msgs/Pose, Twist,
#: Wrench (gazebo_ros_force), trajectory_msgs/JointTrajectory, sensor_msgs/JointState.
MODE = '/atlas/mode'
SET_POSE = '/atlas/set_pose'
CMD_VEL = '/atlas/cmd_vel'
APPLY_PELVIS_FORCE = '/atlas/apply_pelvis_force'
JOINT_TRAJECTORY = '/joint_trajectory'
CONFIGURATION = '/atlas/configuration'
#: JSON, one per applied cheat: when it took effect (sim time, ns) and what, for replay.
SIM_INPUTS = '/atlas/sim_inputs'
#: world -> pelvis from the simulator, and the links (the simulator's, or with
#: tf_publisher:=robot_state_publisher that node's).
TF = '/tf'
#: atlas_msgs/AtlasCommand (2.7.0): commands with k_effort, beside JointCommands.
ATLAS_COMMAND = '/atlas/atlas_command'
#: atlas_msgs/Test: DRCSim's testing hook (joint damping, gains, k_effort).
ATLAS_TEST = '/atlas/debug/test'
#: atlas_msgs/SynchronizationStatistics (DRCSim 2.6+): the synchronization window's delays.
SYNCHRONIZATION_STATISTICS = '/atlas/synchronization_statistics'
#: std_msgs/String (DRCSim 2.6+ cheat): any message ends the window's current wait early.
SYNC_DELAY = '/atlas/debug/sync_delay'
#: atlas_msgs/ResetControls: reset the PID, reload the gains or load an AtlasCommand.
RESET_CONTROLS_SERVICE = '/atlas/reset_controls'
#: The URDF of the simulated model (set by the simulator, or with
#: tf_publisher:=robot_state_publisher by atlas.launch's state_publisher.py).
ROBOT_DESCRIPTION_PARAM = '/robot_description'

#: What scripts/record_run.sh records: the simulator's output, the commands and modes that
#: drove it, the config replay needs, and the log. Analysis and replay read these.
RECORDED_TOPICS: tuple[str, ...] = (
    CLOCK, JOINT_STATES, GROUND_TRUTH_ODOM, IMU, L_FOOT_CONTACT, R_FOOT_CONTACT,
    JOINT_COMMANDS, CONTROL_MODE, SIM_CONFIG, ROSOUT, CONTROLLER_STATISTICS, TF,
    ATLAS_COMMAND, ATLAS_TEST,
    MODE, SET_POSE, CMD_VEL, APPLY_PELVIS_FORCE, JOINT_TRAJECTORY, SIM_INPUTS,
)

#: The ROS 1 message type of each recorded topic, and of the simulator's other topics.
MSG_TYPES: dict[str, str] = {
    CLOCK: 'rosgraph_msgs/Clock',
    JOINT_STATES: 'sensor_msgs/JointState',
    GROUND_TRUTH_ODOM: 'nav_msgs/Odometry',
    IMU: 'sensor_msgs/Imu',
    L_FOOT_CONTACT: 'geometry_msgs/WrenchStamped',
    R_FOOT_CONTACT: 'geometry_msgs/WrenchStamped',
    JOINT_COMMANDS: 'osrf_msgs/JointCommands',
    CONTROL_MODE: 'std_msgs/String',
    SIM_CONFIG: 'std_msgs/String',
    ROSOUT: 'rosgraph_msgs/Log',
    CONTROLLER_STATISTICS: 'atlas_msgs/ControllerStatistics',
    TF: 'tf2_msgs/TFMessage',
    # Published, not recorded by default (README: the 1 kHz duplicates double a bag).
    ATLAS_STATE: 'atlas_msgs/AtlasState',
    FORCE_TORQUE_SENSORS: 'atlas_msgs/ForceTorqueSensors',
    DEBUG_L_FOOT_CONTACT: 'geometry_msgs/WrenchStamped',
    DEBUG_R_FOOT_CONTACT: 'geometry_msgs/WrenchStamped',
    SYNCHRONIZATION_STATISTICS: 'atlas_msgs/SynchronizationStatistics',
    SYNC_DELAY: 'std_msgs/String',
    ATLAS_COMMAND: 'atlas_msgs/AtlasCommand',
    ATLAS_TEST: 'atlas_msgs/Test',
    MODE: 'std_msgs/String',
    SET_POSE: 'geometry_msgs/Pose',
    CMD_VEL: 'geometry_msgs/Twist',
    APPLY_PELVIS_FORCE: 'geometry_msgs/Wrench',
    JOINT_TRAJECTORY: 'trajectory_msgs/JointTrajectory',
    SIM_INPUTS: 'std_msgs/String',
}

#: Gazebo's services, as gazebo_ros offered them.
RESET_WORLD_SERVICE = '/gazebo/reset_world'
RESET_SIMULATION_SERVICE = '/gazebo/reset_simulation'
PAUSE_PHYSICS_SERVICE = '/gazebo/pause_physics'
UNPAUSE_PHYSICS_SERVICE = '/gazebo/unpause_physics'
#: DRCSim 2.x's fork of gazebo_ros_api_plugin named reset_world so ("Reset Model Poses").
RESET_MODELS_SERVICE = '/gazebo/reset_models'

#: Parameters DRCSim loaded and the tutorial reads.
GAINS_PARAM = 'atlas_controller/gains'
TIME_TO_UNPIN_PARAM = '/atlas/time_to_unpin'
#: VRCPlugin's `atlas/startup_mode` (read from the root namespace, as its NodeHandle("")).
STARTUP_MODE_PARAM = '/atlas/startup_mode'

WORLD_FRAME = 'world'
PELVIS_FRAME = 'pelvis'
