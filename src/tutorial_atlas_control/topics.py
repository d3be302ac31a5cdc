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
#: world -> pelvis from the simulator; robot_state_publisher adds the links.
TF = '/tf'
#: The URDF of the simulated model (set by atlas.launch's state_publisher.py).
ROBOT_DESCRIPTION_PARAM = '/robot_description'

#: What scripts/record_run.sh records: the simulator's output, the commands and modes that
#: drove it, the config replay needs, and the log. Analysis and replay read these.
RECORDED_TOPICS: tuple[str, ...] = (
    CLOCK, JOINT_STATES, GROUND_TRUTH_ODOM, IMU, L_FOOT_CONTACT, R_FOOT_CONTACT,
    JOINT_COMMANDS, CONTROL_MODE, SIM_CONFIG, ROSOUT, CONTROLLER_STATISTICS, TF,
)

#: The ROS 1 message type of each recorded topic.
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
}

#: Gazebo's services, as gazebo_ros offered them.
RESET_WORLD_SERVICE = '/gazebo/reset_world'
RESET_SIMULATION_SERVICE = '/gazebo/reset_simulation'
PAUSE_PHYSICS_SERVICE = '/gazebo/pause_physics'
UNPAUSE_PHYSICS_SERVICE = '/gazebo/unpause_physics'

#: Parameters DRCSim loaded and the tutorial reads.
GAINS_PARAM = 'atlas_controller/gains'
TIME_TO_UNPIN_PARAM = '/atlas/time_to_unpin'

WORLD_FRAME = 'world'
PELVIS_FRAME = 'pelvis'
