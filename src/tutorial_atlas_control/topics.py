"""The ROS names the simulator, the tutorial script, the recorder and the bag tools share.

DRCSim's names, kept verbatim so that DRCSim-era clients and `rostopic` habits work.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

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
#: DRCSim 2.6/2.7's AtlasSimInterface (the behaviour library's): behaviour requests and
#: k_effort in; each step's behaviour, its torques (f_out) and feedback out.
ASI_COMMAND = '/atlas/atlas_sim_interface_command'
ASI_STATE = '/atlas/atlas_sim_interface_state'
#: atlas_msgs/AtlasSimInterfaceState for the bag: the same state at ~asi_state_recorded_rate
#: (50 Hz) and at each change of behaviour or status, so that a recorded run keeps every
#: transition without the 1 kHz duplicate.
ASI_STATE_RECORDED = '/atlas/asi_state_recorded'
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
#: robot_state_publisher's latched topic of the fixed joints' transforms.
TF_STATIC = '/tf_static'
#: sensor_msgs/JointState whose position is the world's whole MuJoCo qpos (the robot and
#: anything loose), stamped with its sim time: what the camera node renders, sent while it
#: listens (while someone looks at an image).
RENDER_STATE = '/atlas/render_state'
#: atlas_msgs/VRCScore, latched: DRCSim's VRCScoringPlugin's score of the VRC course (with
#: ~vrc_scoring), every 1 s of sim time and at each gate passed or fall.
VRC_SCORE = '/vrc_score'
#: The MultiSense SL head's laser (sensor_msgs/LaserScan in head_hokuyo_frame), its spindle's
#: speed command (std_msgs/Float64, rad/s) and the spindle's sensor_msgs/JointState
#: (hokuyo_joint), as DRCSim 2.7 named them.
LASER_SCAN = '/multisense_sl/laser/scan'
SET_SPINDLE_SPEED = '/multisense_sl/set_spindle_speed'
HEAD_JOINT_STATES = '/multisense_sl/joint_states'
#: sensor_msgs/Imu of head_imu_link (DRCSim's MultiSenseSL plugin's, 1 kHz).
HEAD_IMU = '/multisense_sl/imu'

class Direction(enum.Enum):
    """Who writes a topic: the simulator node, its users (commands, cheats), or every node."""

    PUBLISHED = 'published'
    SUBSCRIBED = 'subscribed'
    LOG = 'every node'


@dataclass(frozen=True)
class Rate:
    """How often a topic goes out: a rate parameter (Hz of sim time) with its default, or,
    without one (`param` ''), `when` in words."""

    param: str = ''
    default_hz: float = 0.0
    when: str = ''

    @property
    def key(self) -> str:
        """The node's name for it (the stepping loop's `rates_hz` key): '~imu_rate' -> 'imu';
        '' for a rate that is not one of the node's private parameters."""
        if self.param.startswith('~') and self.param.endswith(RATE_SUFFIX):
            return self.param[1:-len(RATE_SUFFIX)]
        return ''

    def text(self) -> str:
        if not self.param:
            return self.when
        hz = f'{self.default_hz:g} Hz' if self.default_hz else 'every step'
        return f'`{self.param}` ({hz}){"; " + self.when if self.when else ""}'


@dataclass(frozen=True)
class Delivery:
    """How the simulator's side writes a topic.

    Attributes:
        message: the name of its wire message in sim.sim_messages.SimMessages ('' when
            the loop builds it otherwise).
        latched: a latched publisher (a bag connection marked latched).
        offline: written by offline runs too (offline/player.py).
        loop: sent by the stepping loop, serialized into its outbox (else the node
            publishes it itself).
    """

    message: str = ''
    latched: bool = False
    offline: bool = False
    loop: bool = False


@dataclass(frozen=True)
class Topic:
    """One row of the simulator's ROS interface (INTERFACE)."""

    name: str
    msg_type: str
    direction: Direction
    rate: Rate = Rate()
    on_demand: bool = False  # filled and sent only while someone subscribes
    recorded: bool = False  # in scripts/record_run.sh's list
    delivery: Delivery = Delivery()


RATE_SUFFIX = '_rate'
EVERY_STEP = Rate(when='every step')
AS_SENT = Rate(when='as sent')
_OUT, _IN = Direction.PUBLISHED, Direction.SUBSCRIBED

#: The simulator's ROS interface, declared once: the stepping loop (what it fills and sends
#: each step), the node (what it advertises and subscribes to), offline runs (what their
#: bags hold), the recorder (RECORDED_TOPICS) and the README's table (markdown_table) read
#: it. A test checks each of them against it.
INTERFACE: tuple[Topic, ...] = (
    Topic(CLOCK, 'rosgraph_msgs/Clock', _OUT, EVERY_STEP, recorded=True,
          delivery=Delivery(offline=True, loop=True)),
    Topic(JOINT_STATES, 'sensor_msgs/JointState', _OUT, Rate('~joint_states_rate', 1000.0),
          recorded=True, delivery=Delivery('joint_state', offline=True, loop=True)),
    Topic(GROUND_TRUTH_ODOM, 'nav_msgs/Odometry', _OUT, Rate('~odom_rate', 100.0),
          recorded=True, delivery=Delivery(offline=True, loop=True)),
    Topic(IMU, 'sensor_msgs/Imu', _OUT, Rate('~imu_rate', 1000.0), recorded=True,
          delivery=Delivery('imu', offline=True, loop=True)),
    Topic(L_FOOT_CONTACT, 'geometry_msgs/WrenchStamped', _OUT, Rate('~contact_rate', 1000.0),
          recorded=True, delivery=Delivery('l', offline=True, loop=True)),
    Topic(R_FOOT_CONTACT, 'geometry_msgs/WrenchStamped', _OUT, Rate('~contact_rate', 1000.0),
          recorded=True, delivery=Delivery('r', offline=True, loop=True)),
    Topic(TF, 'tf2_msgs/TFMessage', _OUT, Rate('~tf_rate', 100.0, (
        'world -> pelvis, with `~tf`; the links at `~links_tf_rate` (50 Hz)')),
          recorded=True, delivery=Delivery(offline=True, loop=True)),
    Topic(CONTROLLER_STATISTICS, 'atlas_msgs/ControllerStatistics', _OUT,
          Rate('/atlas/controller_statistics/update_rate'), on_demand=True, recorded=True,
          delivery=Delivery(loop=True)),
    Topic(ATLAS_STATE, 'atlas_msgs/AtlasState', _OUT, Rate('~atlas_state_rate', 1000.0),
          on_demand=True, delivery=Delivery('atlas_state', loop=True)),
    Topic(FORCE_TORQUE_SENSORS, 'atlas_msgs/ForceTorqueSensors', _OUT,
          Rate('~force_torque_sensors_rate', 1000.0), on_demand=True,
          delivery=Delivery('force_torque_sensors', loop=True)),
    Topic(DEBUG_L_FOOT_CONTACT, 'geometry_msgs/WrenchStamped', _OUT,
          Rate('~debug_contact_rate', 1000.0, 'while the foot touches'), on_demand=True,
          delivery=Delivery('debug_l', loop=True)),
    Topic(DEBUG_R_FOOT_CONTACT, 'geometry_msgs/WrenchStamped', _OUT,
          Rate('~debug_contact_rate', 1000.0, 'while the foot touches'), on_demand=True,
          delivery=Delivery('debug_r', loop=True)),
    Topic(ASI_STATE, 'atlas_msgs/AtlasSimInterfaceState', _OUT, EVERY_STEP, on_demand=True,
          delivery=Delivery(loop=True)),
    Topic(ASI_STATE_RECORDED, 'atlas_msgs/AtlasSimInterfaceState', _OUT,
          Rate('~asi_state_recorded_rate', 50.0, 'and at each change of behaviour or status'),
          on_demand=True, recorded=True, delivery=Delivery(loop=True)),
    Topic(RENDER_STATE, 'sensor_msgs/JointState', _OUT,
          Rate('~render_state_rate', 30.0, "the world's qpos, for the cameras"), on_demand=True,
          delivery=Delivery('render_state', loop=True)),
    Topic(SYNCHRONIZATION_STATISTICS, 'atlas_msgs/SynchronizationStatistics', _OUT,
          Rate(when='every step while the synchronization window is on'),
          delivery=Delivery(latched=True, loop=True)),
    Topic(SIM_CONFIG, 'std_msgs/String', _OUT, Rate(when='at start and after each reset'),
          recorded=True, delivery=Delivery(latched=True, offline=True)),
    Topic(SIM_INPUTS, 'std_msgs/String', _OUT, Rate(when='each applied cheat'), recorded=True),
    Topic(VRC_SCORE, 'atlas_msgs/VRCScore', _OUT,
          Rate(when='with `~vrc_scoring`: every 1 s of sim time and at each gate or fall'),
          recorded=True, delivery=Delivery(latched=True, offline=True)),
    # Offline runs write it when asked (run_offline.py --scans): it costs them a fifth.
    Topic(LASER_SCAN, 'sensor_msgs/LaserScan', _OUT, Rate('~laser_rate', 40.0),
          on_demand=True, recorded=True, delivery=Delivery(loop=True)),
    Topic(HEAD_JOINT_STATES, 'sensor_msgs/JointState', _OUT,
          Rate('~head_joint_states_rate', 1000.0), on_demand=True, delivery=Delivery(loop=True)),
    Topic(HEAD_IMU, 'sensor_msgs/Imu', _OUT, Rate('~head_imu_rate', 1000.0), on_demand=True,
          delivery=Delivery(loop=True)),
    Topic(CURRENT_CONTROL_MODE, 'std_msgs/String', _OUT, Rate(when='each mode switch'),
          delivery=Delivery(latched=True)),
    Topic(TF_STATIC, 'tf2_msgs/TFMessage', _OUT, Rate(when='once (`~tf_publisher` sim)'),
          delivery=Delivery(latched=True)),
    Topic(JOINT_COMMANDS, 'osrf_msgs/JointCommands', _IN, AS_SENT, recorded=True,
          delivery=Delivery(offline=True)),
    Topic(ATLAS_COMMAND, 'atlas_msgs/AtlasCommand', _IN, AS_SENT, recorded=True),
    Topic(ATLAS_TEST, 'atlas_msgs/Test', _IN, AS_SENT, recorded=True),
    Topic(ASI_COMMAND, 'atlas_msgs/AtlasSimInterfaceCommand', _IN, AS_SENT, recorded=True,
          delivery=Delivery(offline=True)),
    Topic(CONTROL_MODE, 'std_msgs/String', _IN, AS_SENT, recorded=True,
          delivery=Delivery(offline=True)),
    Topic(MODE, 'std_msgs/String', _IN, AS_SENT, recorded=True),
    Topic(SET_POSE, 'geometry_msgs/Pose', _IN, AS_SENT, recorded=True),
    Topic(CMD_VEL, 'geometry_msgs/Twist', _IN, AS_SENT, recorded=True),
    Topic(APPLY_PELVIS_FORCE, 'geometry_msgs/Wrench', _IN, AS_SENT, recorded=True),
    Topic(JOINT_TRAJECTORY, 'trajectory_msgs/JointTrajectory', _IN, AS_SENT, recorded=True),
    Topic(CONFIGURATION, 'sensor_msgs/JointState', _IN, AS_SENT),
    Topic(SET_SPINDLE_SPEED, 'std_msgs/Float64', _IN, AS_SENT, recorded=True),
    Topic(SYNC_DELAY, 'std_msgs/String', _IN, AS_SENT),
    Topic(ROSOUT, 'rosgraph_msgs/Log', Direction.LOG, Rate(when='each log line'), recorded=True,
          delivery=Delivery(offline=True)),
)

#: The table's rows by topic.
BY_NAME: dict[str, Topic] = {topic.name: topic for topic in INTERFACE}
#: What scripts/record_run.sh records: the simulator's output, the commands and modes that
#: drove it, the config replay needs, and the log. Analysis and replay read these.
RECORDED_TOPICS: tuple[str, ...] = tuple(topic.name for topic in INTERFACE if topic.recorded)
#: The ROS 1 message type of each topic of the interface.
MSG_TYPES: dict[str, str] = {topic.name: topic.msg_type for topic in INTERFACE}


def markdown_table() -> str:
    """INTERFACE as the README's markdown table (one row per topic, in the table's order)."""
    yes = {True: 'yes', False: 'no'}
    lines = ['| Topic | Type | Direction | Rate (parameter, default) | On demand | Recorded |',
             '| --- | --- | --- | --- | --- | --- |']
    lines += [f'| `{topic.name}` | `{topic.msg_type}` | {topic.direction.value} | '
              f'{topic.rate.text()} | {yes[topic.on_demand]} | {yes[topic.recorded]} |'
              for topic in INTERFACE]
    return '\n'.join(lines) + '\n'


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

#: The multisense_sl head's stereo cameras (stereo/; rendered by multisense_cameras.py).
CAMERA_NAMESPACE = '/multisense_sl/camera'
SET_FPS = '/multisense_sl/set_fps'
#: What record_run.sh adds with atlas.launch's record_images:=true: the images as JPEG
#: (image_transport's compressed topic names) and their camera_info; never the raw images.
IMAGE_RECORDED_TOPICS: tuple[str, ...] = tuple(
    f'{CAMERA_NAMESPACE}/{side}/{name}' for side in ('left', 'right')
    for name in ('image_raw/compressed', 'camera_info'))

#: The VRC course's static shapes for rviz (course_markers.py; latched, published once).
COURSE_MARKERS_TOPIC = '/vrc_course/markers'
