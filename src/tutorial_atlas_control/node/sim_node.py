"""The simulator node: AtlasSimulator behind DRCSim's ROS interface.

The rospy shell around the stepping loop (stepping/loop.py, no ROS): publishers,
subscriptions, services, parameters and the viewer window. Publishes /clock,
/atlas/joint_states, /ground_truth_odom, /atlas/imu and the foot contact wrenches in sim
time, /atlas/controller_statistics (command age, while subscribed), DRCSim's
/atlas/atlas_state, /atlas/force_torque_sensors and /atlas/debug/{l,r}_foot_contact (while
subscribed), and a latched
/atlas/sim_config (JSON: timestep, time_to_unpin, model file and checksum, time of the last
reset) for offline replay; obeys /atlas/joint_commands, /atlas/atlas_command,
/atlas/debug/test and /atlas/control_mode; serves DRCSim 2.7's AtlasSimInterface
(/atlas/atlas_sim_interface_command in, /atlas/atlas_sim_interface_state out every step while
subscribed; asi/); offers /atlas/reset_controls and gazebo_ros's
reset and pause services (and DRCSim's /gazebo/reset_models). VRCPlugin's
/atlas/mode, set_pose, cmd_vel, gazebo_ros_force's /atlas/apply_pelvis_force and
gazebo_ros_joint_trajectory's /joint_trajectory are checked here and applied by the loop
(sim/vrc.py), each applied one echoed on /atlas/sim_inputs; /atlas/configuration is
logged as not implemented, as in DRCSim. Publishes a latched /atlas/current_control_mode (the
mode now). Logs one line per fall (sim/fall.py's: the pelvis less than 0.5 m above the
ground under the feet, once until a reset) and per reset, and warns when joint commands
arrive in a mode that does not apply them.

Parameters (private unless noted):
    ~real_time_factor (float, 1.0): sim time per wall time; 0 runs as fast as possible.
    ~paused (bool, false): start with physics paused (/gazebo/unpause_physics starts it).
    ~gui (bool, false): open the MuJoCo viewer (needs a display; a $DISPLAY no X server
        answers gives one warning and a headless run); its Reset button and key (Backspace)
        and Shift+Ctrl+R do reset_world, Space pauses/unpauses (viewer.py).
    ~joint_states_rate, ~imu_rate, ~contact_rate (Hz, 1000): 0 or >= 1000 = every step.
    ~atlas_state_rate, ~force_torque_sensors_rate, ~debug_contact_rate (Hz, 1000): DRCSim's
        /atlas/atlas_state, /atlas/force_torque_sensors, /atlas/debug/{l,r}_foot_contact
        (those only while the foot touches something); each filled only while subscribed.
    ~odom_rate (Hz, 100): /ground_truth_odom rate, as DRCSim.
    ~tf (bool, true): broadcast world -> pelvis on /tf from the ground truth (and, with
        ~tf_publisher sim, the links), if the model
        has a matching URDF (urdf.matching_urdf); else one warning and no /tf.
    ~tf_rate (Hz, 100): /tf rate.
    ~tf_publisher (str, sim): who publishes the links' transforms. sim: this node sets
        /robot_description and publishes, in robot_state_publisher's stead and equal to
        it, every moving joint's transform on /tf at ~links_tf_rate (Hz of sim time, 50)
        and the fixed joints on latched /tf_static (sim/link_transforms.py);
        robot_state_publisher: atlas.launch's state_publisher.py does both.
    ~bag_dir (str, unset): where the launch's recorder writes; if set and no file can be
        written there, the node refuses to start (one line).
    ~recorder_send_period (s of wall time, 0.004): what the launch's recorder (/recorder)
        subscribes to is sent to it this often, in one send per topic, instead of after
        every step as to any other subscriber (node/held_sends.py); 0: after every step.
    ~stand (str, balance): what Stand does. balance: the open AtlasSimInterface's balancing
        Stand (balance/, docs/controllers.md) whenever Stand is asked for (an ASI STAND,
        /atlas/control_mode Stand, bdi_stand's sequence); a (re)start in Stand holds the robot
        with the parameter gains, the tutorial's start, until then. hold: Stand is that joint
        hold (DRCSim 2.5.2's stand-in for BDI's behaviour) until a bdi_stand sequence asks for
        BDI's Stand.
    ~behaviour (str, ''): a behaviour of the user's own (module:Class or file.py:Class,
        asi/user_behaviour.py), registered over the library's Stand, Walk or Step; needs
        ~stand balance.
    ~model_file (str, the package's sim/atlas_v1.xml): the MJCF to simulate; it must have
        Atlas v1's joints, actuators and sensors (a variant of the package's model).
    ~start (str, ''): where the robot starts and every reset puts it: a VRC Task 2 world's
        start by name (vrc_task_2, vrc_task_2_mud_start, ...) or 'x y z yaw' (m, rad); the
        pelvis at (x, y) turned by yaw, its z putting the soles on the model's ground (z is
        a hint only). '': the model file's spawn (atlas_v1.xml's at the origin).
    ~vrc_scoring (bool, false): score the run as DRCSim's VRCScoringPlugin scored VRC Task 2
        (the VRC launches set it): /vrc_score (latched, atlas_msgs/VRCScore) and score.log
        in ~score_dir, every 1 s of sim time and at each gate or fall (stepping/course_scoring.py).
    ~score_dir (str, /tmp/vrc_task_2): where score.log goes (created if missing; refused in
        one line if it cannot be written).
    /atlas/time_to_unpin (float, 1.0): seconds the torso stays pinned after start/reset.
    /atlas/startup_mode (str, pinned_with_gravity): VRCPlugin's start (sim/vrc.py STARTUP_MODES).
    atlas_controller/gains/<joint>/{p,i,d,i_clamp}: the gains Stand/Freeze/User-hold use.
    atlas_controller/statistics_time_window_size (s, 1.0): window of the command age statistics.
    /atlas/controller_statistics/update_rate (Hz, unset = every step): clamped to 1..10000.
    /atlas/delay_window_size (s, 5.0), /atlas/delay_max_per_window (s, 0.25),
        /atlas/delay_max_per_step (s, 0.025): DRCSim 2.6's synchronization window budgets
        (wall time; stepping/synchronization.py), used while an AtlasCommand's
        desired_controller_period_ms is non-zero; /atlas/synchronization_statistics is then
        published every step, and a message on /atlas/debug/sync_delay ends a wait early.
"""

from __future__ import annotations

import io
import time
import warnings
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import genpy
import rospy
from atlas_msgs.msg import (
    AtlasCommand,
    AtlasSimInterfaceCommand,
    AtlasSimInterfaceState,
    AtlasState,
    ControllerStatistics,
    ForceTorqueSensors,
    SynchronizationStatistics,
    Test,
    VRCScore,
)
from atlas_msgs.srv import ResetControls, ResetControlsResponse
from geometry_msgs.msg import TransformStamped, WrenchStamped
from nav_msgs.msg import Odometry
from osrf_msgs.msg import JointCommands
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState, LaserScan
from std_msgs.msg import Float64, String
from std_srvs.srv import Empty, EmptyResponse
from tf2_msgs.msg import TFMessage

from tutorial_atlas_control import topics
from tutorial_atlas_control.asi import load_user_behaviour
from tutorial_atlas_control.bags import unwritable_reason
from tutorial_atlas_control.control_modes import ControlMode
from tutorial_atlas_control.course import (
    DEFAULT_SCORE_DIR,
    MUD_DAMPING,
    CourseError,
    ScoreRow,
    Start,
    check_mud_damping,
    parse_start,
)
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.node.cheats import WARN_THROTTLE_S, subscribe_cheats
from tutorial_atlas_control.node.held_sends import RECORDER_SEND_PERIOD_S, HeldSends
from tutorial_atlas_control.node.master_watch import start_master_watch
from tutorial_atlas_control.node.recorder_watch import RECORDER_NODE, start_recorder_watch
from tutorial_atlas_control.node.transport import (
    ConnectionWriter,
    WireBatch,
    flush_queued,
    flush_rosout,
    widen_accept_queue,
)
from tutorial_atlas_control.node.udpros import serve as serve_udpros
from tutorial_atlas_control.node.viewer_window import open_viewer
from tutorial_atlas_control.sensors import spindle_command
from tutorial_atlas_control.sim import (
    DEFAULT_STARTUP_MODE,
    DEFAULT_TIME_TO_UNPIN_S,
    DEFAULT_WINDOW_S,
    MODEL_PATH,
    STARTUP_MODES,
    UPDATE_RATE_PARAM,
    WINDOW_PARAM,
    AtlasSimulator,
    CommandAgeStatistics,
    GainsError,
    LinkTransforms,
    ModeError,
    UrdfError,
    VrcMode,
    gains_from_params,
    load_model,
    matching_urdf,
    parse_mode,
    read_joints,
)
from tutorial_atlas_control.stepping import (
    LINKS_TF_RATE_HZ,
    DelayBudgets,
    LoopOutputs,
    LoopSettings,
    ResetControlsRequest,
    SteppingLoop,
    SynchronizationWindow,
    default_rates_hz,
)
from tutorial_atlas_control.units import finite_number

NODE_NAME = 'atlas_sim'
#: Who publishes the links' transforms (~tf_publisher; the first is the default).
TF_PUBLISHERS = ('sim', 'robot_state_publisher')
#: The classes of the messages the node publishes, by ROS type (topics.INTERFACE's).
MESSAGE_CLASSES: dict[str, type[genpy.Message]] = {cls._type: cls for cls in (
    Clock, JointState, Odometry, Imu, WrenchStamped, ControllerStatistics, AtlasState,
    ForceTorqueSensors, SynchronizationStatistics, TFMessage, String, AtlasSimInterfaceState,
    VRCScore, LaserScan)}
#: What ~stand chooses Stand to be (the first is the default).
STAND_CHOICES = ('balance', 'hold')
#: Queue size of the publishers the node itself calls publish() on (1 when not named).
#: A reset's /atlas/sim_config must reach the bag (replay reads it): resets one step apart
#: (a diverging model's) published two before rospy's writer took the first.
QUEUE_SIZES = {topics.SIM_INPUTS: 100, topics.SIM_CONFIG: 100}


class RawMessage(genpy.Message):
    """A command message as it arrives, left undecoded by rospy.

    genpy's decoder would run in the receiving thread, under the GIL the stepping loop
    needs, and at thousands of commands a second starve the loop. A subclass keeps the real
    type, MD5 and definition, so the subscription is registered, negotiated and shown as
    that type; the loop decodes `raw` itself (msgs/joint_commands.py, msgs/atlas_command.py).
    """

    _has_header = True
    __slots__ = ['raw']

    def __init__(self) -> None:
        self.raw = b''

    def deserialize(self, str: bytes) -> RawMessage:  # noqa: A002 - genpy's name
        self.raw = str
        return self


class RawJointCommands(RawMessage):
    """osrf_msgs/JointCommands, undecoded."""

    _type = JointCommands._type
    _md5sum = JointCommands._md5sum
    _full_text = JointCommands._full_text
    __slots__: list[str] = []


class RawAtlasCommand(RawMessage):
    """atlas_msgs/AtlasCommand, undecoded."""

    _type = AtlasCommand._type
    _md5sum = AtlasCommand._md5sum
    _full_text = AtlasCommand._full_text
    __slots__: list[str] = []


class RawTest(RawMessage):
    """atlas_msgs/Test, undecoded (it goes through the loop's queue, in order)."""

    _type = Test._type
    _md5sum = Test._md5sum
    _full_text = Test._full_text
    __slots__: list[str] = []


class RawAsiCommand(RawMessage):
    """atlas_msgs/AtlasSimInterfaceCommand, undecoded (through the loop's queue, in order)."""

    _type = AtlasSimInterfaceCommand._type
    _md5sum = AtlasSimInterfaceCommand._md5sum
    _full_text = AtlasSimInterfaceCommand._full_text
    __slots__: list[str] = []


class RawLatched:
    """A pre-serialized message as rospy's latch: what a new subscriber of a latched
    publisher gets first (rospy serializes the latch with serialize_message)."""

    _has_header = False

    def __init__(self, data: bytes) -> None:
        self.data = data

    def serialize(self, buff: io.BytesIO) -> None:
        buff.write(self.data)


class RosLog:
    """The stepping loop's log lines, into rospy's log (stepping.outputs.LoopLog).

    Refusals are throttled per topic and kind (rospy's logwarn_throttle throttles per call
    site, so a refused JointCommands would hide a refused AtlasCommand for WARN_THROTTLE_S).
    """

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        self._clock = clock
        self._last_s: dict[tuple[str, str], float] = {}

    def _throttled(self, key: tuple[str, str], text: str) -> None:
        now_s = self._clock()
        last_s = self._last_s.get(key)
        if last_s is None or now_s - last_s >= WARN_THROTTLE_S:
            self._last_s[key] = now_s
            rospy.logwarn(text)

    @staticmethod
    def info(text: str) -> None:
        rospy.loginfo(text)

    def refused_command(self, text: str, topic: str = topics.JOINT_COMMANDS) -> None:
        self._throttled(('refused', topic), text)

    def kept_fields(self, text: str, topic: str) -> None:
        self._throttled(('kept', topic), text)

    @staticmethod
    def warn(text: str) -> None:
        rospy.logwarn(text)

    @staticmethod
    def error(text: str) -> None:
        rospy.logerr(text)

    @staticmethod
    def fatal(text: str) -> None:
        rospy.logfatal(text)


class SimNode:
    """The stepping loop (stepping/loop.py) behind ROS: publishers, subscriptions,
    services, parameters and the viewer window.

    Args:
        settings: the loop's rates, pace and pause, and the links' transforms to publish
            (with `tf` only).
        tf: publish /tf (and, with settings.links, the links and /tf_static).
        recorder_send_period_s: how often the recorder's bytes go out (held_sends.py).
    """

    def __init__(self, sim: AtlasSimulator, settings: LoopSettings, gui: bool,
                 tf: bool = False, sync_budgets: DelayBudgets | None = None,
                 recorder_send_period_s: float = RECORDER_SEND_PERIOD_S) -> None:
        self.sim = sim
        self.gui = gui
        # UDPROS for roscpp's unreliable() subscribers, before the master announces a topic.
        self.udpros = serve_udpros()
        widen_accept_queue()  # a dozen subscribers connect at once when it advertises
        self._advertise(tf, settings.score_dir is not None)
        outbox = WireBatch(ConnectionWriter(held=HeldSends({RECORDER_NODE},
                                                           recorder_send_period_s)))
        # Before rospy closes the connections: what a stalled-then-live subscriber (the
        # recorder) has not taken yet (transport.ConnectionWriter.drain).
        rospy.on_shutdown(outbox.drain)
        links = settings.links if tf else None
        outputs = LoopOutputs(outbox, self.publishers, RosLog(), self._publish_config,
                              self._publish_input, self._latch_synchronization,
                              self._publish_score)
        self.loop = SteppingLoop(sim, outputs, replace(settings, links=links),
                                 self._controller_statistics(),
                                 synchronization=SynchronizationWindow(
                                     sync_budgets or DelayBudgets()))
        if links is not None:
            self._publish_static_transforms(links)
        self.loop.publish_config()
        self.node_publishers[topics.CURRENT_CONTROL_MODE].publish(String(data=sim.mode.value))
        self._subscribe()

    def _advertise(self, tf: bool, scored: bool) -> None:
        """The publishers of topics.INTERFACE: the loop's (`publishers`), whose messages it
        serializes itself (msgs/wire.py), and the node's own (`node_publishers`).

        The loop's have queue_size=None: plain synchronous connections, without rospy's
        per-message writer-thread handoff. A subscriber that cannot keep up slows the loop
        (TCP back-pressure) instead of losing messages; one that stops reading is not
        waited for, and is dropped once it has accepted nothing for
        transport.SEND_TIMEOUT_S (node/transport.py). /vrc_score only in a scored run.
        """
        self.publishers: dict[str, rospy.Publisher] = {}
        self.node_publishers: dict[str, rospy.Publisher] = {}
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', SyntaxWarning)  # rospy: "explicit queue_size"
            for topic in topics.INTERFACE:
                if topic.direction is not topics.Direction.PUBLISHED or (
                        topic.name == topics.TF and not tf) or (
                        topic.name == topics.VRC_SCORE and not scored):
                    continue
                name, latch = topic.name, topic.delivery.latched
                if topic.delivery.loop:
                    self.publishers[name] = rospy.Publisher(
                        name, MESSAGE_CLASSES[topic.msg_type], queue_size=None, latch=latch)
                elif name != topics.TF_STATIC:  # only with the links (see __init__)
                    self.node_publishers[name] = rospy.Publisher(
                        name, MESSAGE_CLASSES[topic.msg_type],
                        queue_size=QUEUE_SIZES.get(name, 1), latch=latch)

    def _publish_static_transforms(self, links: LinkTransforms) -> None:
        """The fixed joints once on latched /tf_static, as robot_state_publisher 1.15 does
        (an empty message for a robot without any)."""
        stamp = genpy.Time(*divmod(self.sim.sim_time_ns, 1_000_000_000))
        message = TFMessage()
        for fixed in links.static:
            transform = TransformStamped()
            transform.header.stamp = stamp
            transform.header.frame_id, transform.child_frame_id = fixed.parent, fixed.child
            t, r = transform.transform.translation, transform.transform.rotation
            t.x, t.y, t.z = (float(v) for v in fixed.translation_m)
            r.x, r.y, r.z, r.w = (float(v) for v in fixed.rotation_xyzw)
            message.transforms.append(transform)
        self.node_publishers[topics.TF_STATIC] = rospy.Publisher(
            topics.TF_STATIC, TFMessage, queue_size=1,
            latch=topics.BY_NAME[topics.TF_STATIC].delivery.latched)
        self.node_publishers[topics.TF_STATIC].publish(message)

    def _controller_statistics(self) -> CommandAgeStatistics:
        """DRCSim's command age statistics, from the parameters (fed and published by the
        loop only while someone subscribes)."""
        rate_hz = rospy.get_param(UPDATE_RATE_PARAM) if rospy.has_param(UPDATE_RATE_PARAM) else None
        return CommandAgeStatistics(
            self.sim.dt_s, rospy.get_param(WINDOW_PARAM, DEFAULT_WINDOW_S), rate_hz)

    def _subscribe(self) -> None:
        """The command and mode subscriptions and gazebo_ros's services."""
        rospy.Subscriber(topics.JOINT_COMMANDS, RawJointCommands, self.on_joint_commands,
                         queue_size=10, tcp_nodelay=True)
        rospy.Subscriber(topics.ATLAS_COMMAND, RawAtlasCommand, self.on_atlas_command,
                         queue_size=10, tcp_nodelay=True)
        rospy.Subscriber(topics.ATLAS_TEST, RawTest, self.on_test, queue_size=10)
        rospy.Subscriber(topics.ASI_COMMAND, RawAsiCommand, self.on_asi_command, queue_size=1,
                         tcp_nodelay=True)
        rospy.Subscriber(topics.CONTROL_MODE, String, self.on_control_mode, queue_size=10)
        rospy.Subscriber(topics.SET_SPINDLE_SPEED, Float64, self.on_spindle_speed, queue_size=10)
        # DRCSim 2.6's cheat: any message ends the synchronization window's wait early.
        rospy.Subscriber(topics.SYNC_DELAY, String, lambda _msg: self.loop.wake(), queue_size=1,
                         tcp_nodelay=True)
        rospy.on_shutdown(self.loop.stop_waiting)  # a wait in progress ends at once
        loop = self.loop
        self.services = [
            rospy.Service(topics.RESET_CONTROLS_SERVICE, ResetControls, self.on_reset_controls),
            rospy.Service(topics.RESET_WORLD_SERVICE, Empty, self._service(loop.reset_world)),
            rospy.Service(topics.RESET_SIMULATION_SERVICE, Empty,
                          self._service(loop.reset_simulation)),
            rospy.Service(topics.PAUSE_PHYSICS_SERVICE, Empty, self._service(loop.pause)),
            rospy.Service(topics.UNPAUSE_PHYSICS_SERVICE, Empty, self._service(loop.unpause)),
            rospy.Service(topics.RESET_MODELS_SERVICE, Empty, self._service(loop.reset_world)),
        ]
        subscribe_cheats(self.sim, loop.apply_input)

    def _latch_synchronization(self, message: bytes) -> None:
        """The latest /atlas/synchronization_statistics (without its length prefix), for
        subscribers to come."""
        self.publishers[topics.SYNCHRONIZATION_STATISTICS].impl.latch = RawLatched(message)

    def _publish_input(self, text: str) -> None:
        """/atlas/sim_inputs (recorded): one applied cheat."""
        self.node_publishers[topics.SIM_INPUTS].publish(String(data=text))

    def _publish_score(self, row: ScoreRow) -> None:
        """/vrc_score (latched, recorded): a row of the course's scoring."""
        self.node_publishers[topics.VRC_SCORE].publish(VRCScore(
            wall_time=_ros_time(row.wall_elapsed_ns), sim_time=_ros_time(row.sim_time_ns),
            wall_time_elapsed=_ros_time(row.wall_since_gate0_ns),
            sim_time_elapsed=_ros_time(row.sim_since_gate0_ns),
            completion_score=row.completion, falls=row.falls, message=row.message,
            task_type=row.task_type))

    def _publish_config(self, text: str) -> None:
        """/atlas/sim_config (latched, recorded in every bag): what replay needs."""
        self.node_publishers[topics.SIM_CONFIG].publish(String(data=text))

    # -- subscriptions and services ----------------------------------------------------
    def on_joint_commands(self, msg: RawJointCommands) -> None:
        """Hand the raw message to the loop, which decodes it before its next step."""
        self.loop.receive_command(msg.raw)

    def on_atlas_command(self, msg: RawAtlasCommand) -> None:
        self.loop.receive_command(msg.raw, topics.ATLAS_COMMAND)

    def on_test(self, msg: RawTest) -> None:
        self.loop.receive_command(msg.raw, topics.ATLAS_TEST)

    def on_asi_command(self, msg: RawAsiCommand) -> None:
        self.loop.receive_command(msg.raw, topics.ASI_COMMAND)

    def on_reset_controls(self, request: ResetControls._request_class
                          ) -> ResetControlsResponse:
        """atlas_msgs/ResetControls: the loop checks and applies it (stepping/controls.py)."""
        gains = None
        if request.reload_pid_from_ros:
            try:
                gains = gains_from_params(rospy.get_param(topics.GAINS_PARAM, {}))
            except GainsError as err:
                gains = str(err)
        buffer = io.BytesIO()
        request.atlas_command.serialize(buffer)
        success, status = self.loop.reset_controls(ResetControlsRequest(
            bool(request.reset_bdi_controller), bool(request.reset_pid_controller),
            bool(request.reload_pid_from_ros), buffer.getvalue(), gains))
        if success:
            rospy.loginfo(f'{topics.RESET_CONTROLS_SERVICE}: {status}')
        else:
            rospy.logwarn(f'refused {topics.RESET_CONTROLS_SERVICE}: {status}')
        return ResetControlsResponse(success=success, status_message=status)

    def on_control_mode(self, msg: String) -> None:
        try:
            mode = parse_mode(msg.data)
        except ModeError as err:
            rospy.logwarn_throttle(WARN_THROTTLE_S, f'refused /atlas/control_mode: {err}')
            return
        if mode is ControlMode.WALK and not self.loop.asi.serves(ControlMode.WALK):
            rospy.logwarn_throttle(WARN_THROTTLE_S, 'refused /atlas/control_mode: Walk needs '
                                   'the balancing Stand (stand:=balance, the default, '
                                   'or /atlas/mode bdi_stand first)')
            return
        previous = self.loop.set_mode(mode)
        self.node_publishers[topics.CURRENT_CONTROL_MODE].publish(String(data=mode.value))
        rospy.loginfo(f'control mode: {previous.value} -> {mode.value}')

    def on_spindle_speed(self, msg: Float64) -> None:
        """The laser spindle's speed, taken as DRCSim took it (sensors/spindle.py): one
        warning line when it is clamped or, NaN, ignored."""
        command = spindle_command(float(msg.data))
        if command.warning:
            rospy.logwarn_throttle(WARN_THROTTLE_S, command.warning)
        if command.speed is not None:
            self.loop.set_spindle_speed(command.speed)

    def _service(self, action: Callable[[], None]) -> Callable[[object], EmptyResponse]:
        def handle(_request: object) -> EmptyResponse:
            action()
            return EmptyResponse()
        return handle

    # -- the loop ------------------------------------------------------------------------
    def spin(self) -> int:
        """Run the stepping loop until ROS shuts down (with the viewer, if asked); the exit
        status."""
        viewer = open_viewer(self.sim, self.loop) if self.gui else None
        # One line if the recorder goes (killed, disk full) while the simulation goes on;
        # registered again with a restarted master.
        watch = start_recorder_watch(self.publishers[topics.JOINT_STATES],
                                     lambda: self.sim.sim_time_ns * 1e-9, time.monotonic)
        start_master_watch(watch)
        status = self.loop.run(rospy.is_shutdown)
        watch.set()
        if status:  # the last reset's config and the line saying why reach the recorder
            flush_queued(self.node_publishers[topics.SIM_CONFIG])
            flush_rosout()
            rospy.signal_shutdown('physics diverges after every reset')
        if viewer is not None:
            viewer.close()
        return status


def _ros_time(ns: int) -> genpy.Time:
    return genpy.Time(*divmod(ns, 1_000_000_000))


def _score_dir() -> Path | None:
    """~vrc_scoring and ~score_dir: where score.log goes, or None for an unscored run."""
    scoring = rospy.get_param('~vrc_scoring', False)
    if not isinstance(scoring, bool):
        raise AtlasControlError(f'parameter {rospy.resolve_name("~vrc_scoring")} must be true '
                                f'or false, got {scoring!r}')
    score_dir = rospy.get_param('~score_dir', str(DEFAULT_SCORE_DIR))
    if not isinstance(score_dir, str) or not score_dir:
        raise AtlasControlError(f'parameter {rospy.resolve_name("~score_dir")} must be a '
                                f'directory, got {score_dir!r}')
    return Path(score_dir).expanduser() if scoring else None


def _float_param(name: str, default: float, minimum: float = 0.0) -> float:
    value = rospy.get_param(name, default)
    number = finite_number(value)
    if number is None or number < minimum:
        raise AtlasControlError(f'parameter {rospy.resolve_name(name)} must be a number '
                                f'>= {minimum}, got {value!r}')
    return number


def build_node() -> SimNode:
    """Read parameters, load the model and gains; raise AtlasControlError on bad ones."""
    _check_bag_dir()
    gains = gains_from_params(rospy.get_param(topics.GAINS_PARAM, {}))
    time_to_unpin_s = _float_param(topics.TIME_TO_UNPIN_PARAM, DEFAULT_TIME_TO_UNPIN_S)
    # Each rate of topics.INTERFACE from its parameter (~joint_states_rate, ...).
    rates_hz = {key: _float_param(f'~{key}{topics.RATE_SUFFIX}', default_hz)
                for key, default_hz in default_rates_hz().items()}
    rates_hz['links_tf'] = _float_param('~links_tf_rate', LINKS_TF_RATE_HZ, minimum=1.0)
    tf_publisher = rospy.get_param('~tf_publisher', TF_PUBLISHERS[0])
    if tf_publisher not in TF_PUBLISHERS:
        raise AtlasControlError(f'parameter {rospy.resolve_name("~tf_publisher")} must be one '
                                f'of {", ".join(TF_PUBLISHERS)}, got {tf_publisher!r}')
    model_file = rospy.get_param('~model_file', str(MODEL_PATH))
    if not isinstance(model_file, str) or not model_file:
        raise AtlasControlError(f'parameter {rospy.resolve_name("~model_file")} must be the '
                                f'path of an MJCF file, got {model_file!r}')
    startup_mode = rospy.get_param(topics.STARTUP_MODE_PARAM, DEFAULT_STARTUP_MODE.value)
    if startup_mode not in STARTUP_MODES:
        raise AtlasControlError(f'parameter {topics.STARTUP_MODE_PARAM} must be one of '
                                f'{", ".join(STARTUP_MODES)}, got {startup_mode!r}')
    stand = rospy.get_param('~stand', STAND_CHOICES[0])
    if stand not in STAND_CHOICES:
        raise AtlasControlError(f'parameter {rospy.resolve_name("~stand")} must be one of '
                                f'{", ".join(STAND_CHOICES)}, got {stand!r}')
    sim = AtlasSimulator(load_model(Path(model_file)), gains, time_to_unpin_s,
                         startup_mode=VrcMode(startup_mode), start=_start_param(),
                         mud_damping=_mud_damping_param())
    sim.sensor_seed = _sensor_seed_param()
    behaviour_spec = rospy.get_param('~behaviour', '')
    if not isinstance(behaviour_spec, str):
        raise AtlasControlError(f'parameter {rospy.resolve_name("~behaviour")} must be '
                                f'module:Class or file.py:Class, got {behaviour_spec!r}')
    if behaviour_spec and stand != 'balance':
        raise AtlasControlError(f'parameter {rospy.resolve_name("~behaviour")} needs '
                                f'~stand balance (the library it joins), got {stand!r}')
    user_behaviour = (load_user_behaviour(behaviour_spec, sim.atlas) if behaviour_spec
                      else None)
    description = _tf_wanted(Path(model_file), sim)
    settings = LoopSettings(rates_hz, _float_param('~real_time_factor', 1.0),
                            bool(rospy.get_param('~paused', False)),
                            _links_publisher(description) if tf_publisher == 'sim' else None,
                            balance_stand=stand == 'balance',
                            hold_at_start=stand == 'balance',
                            user_behaviour=user_behaviour, score_dir=_score_dir())
    return SimNode(sim, settings, bool(rospy.get_param('~gui', False)),
                   description is not None, DelayBudgets.from_params(rospy.get_param),
                   _float_param('~recorder_send_period', RECORDER_SEND_PERIOD_S))


def _sensor_seed_param() -> int:
    """~sensor_seed: the seed of the head's laser noise (a non-negative integer, default 0)."""
    seed = rospy.get_param('~sensor_seed', 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise AtlasControlError(f'parameter {rospy.resolve_name("~sensor_seed")} must be a '
                                f'non-negative integer, got {seed!r}')
    return seed


def _mud_damping_param() -> float:
    """~mud_damping: the MudPlugin's damping (N s/m) in a world with a `mud_atlas` box
    (sim.mud); its error names the parameter."""
    return check_mud_damping(rospy.get_param('~mud_damping', MUD_DAMPING),
                             f'parameter {rospy.resolve_name("~mud_damping")}')


def _start_param() -> Start | None:
    """~start as a start (None: unset or ''); its error names the parameter."""
    text = rospy.get_param('~start', '')
    try:
        return parse_start(text if isinstance(text, str) else repr(text))
    except CourseError as err:
        raise AtlasControlError(f'parameter {rospy.resolve_name("~start")}: {err}') from None


def _check_bag_dir() -> None:
    """~bag_dir (set by atlas.launch when it records): refuse to run unrecorded from the start."""
    bag_dir = rospy.get_param('~bag_dir', '')
    if not bag_dir:
        return
    reason = unwritable_reason(Path(str(bag_dir)).expanduser())
    if reason is not None:
        raise AtlasControlError(f'bag_dir {bag_dir} cannot be written ({reason}): the run would '
                                'not be recorded; give a writable bag_dir:=, or record:=false')


def _tf_wanted(model_file: Path, sim: AtlasSimulator) -> str | None:
    """The model's URDF if ~tf, unless the model has none matching: then one warning
    saying why, and None (as for ~tf false)."""
    if not rospy.get_param('~tf', True):
        return None
    try:
        _path, description = matching_urdf(model_file, sim.model)
    except UrdfError as err:
        rospy.logwarn(f'TF is off: {err}; rviz cannot show this model '
                      '(write a matching URDF beside it to get TF)')
        return None
    return description


def _links_publisher(description: str | None) -> LinkTransforms | None:
    """~tf_publisher sim: set /robot_description (for rviz) and publish the links' TF
    from `description`'s joints; None without TF."""
    if description is None:
        return None
    rospy.set_param(topics.ROBOT_DESCRIPTION_PARAM, description)
    _links, joints = read_joints(description)
    return LinkTransforms(joints, JOINT_NAMES)
