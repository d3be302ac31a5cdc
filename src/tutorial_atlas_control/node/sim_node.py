"""The simulator node: AtlasSimulator behind DRCSim's ROS interface.

The rospy shell around the stepping loop (stepping/loop.py, no ROS): publishers,
subscriptions, services, parameters and the viewer window. Publishes /clock,
/atlas/joint_states, /ground_truth_odom, /atlas/imu and the foot contact wrenches in sim
time, /atlas/controller_statistics (command age, while subscribed), DRCSim's
/atlas/atlas_state, /atlas/force_torque_sensors and /atlas/debug/{l,r}_foot_contact (while
subscribed), and a latched
/atlas/sim_config (JSON: timestep, time_to_unpin, model file and checksum, time of the last
reset) for offline replay; obeys /atlas/joint_commands, /atlas/atlas_command,
/atlas/debug/test and /atlas/control_mode; offers /atlas/reset_controls and gazebo_ros's
reset and pause services (and DRCSim's /gazebo/reset_models). VRCPlugin's
/atlas/mode, set_pose, cmd_vel, gazebo_ros_force's /atlas/apply_pelvis_force and
gazebo_ros_joint_trajectory's /joint_trajectory are checked here and applied by the loop
(sim/vrc.py), each applied one echoed on /atlas/sim_inputs; /atlas/configuration is
logged as not implemented, as in DRCSim. Publishes a latched /atlas/current_control_mode (the
mode now). Logs one line per fall (pelvis below 0.5 m, once until a reset) and per reset,
and warns when joint commands arrive in a mode that does not apply them.

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
    ~model_file (str, the package's sim/atlas_v1.xml): the MJCF to simulate; it must have
        Atlas v1's joints, actuators and sensors (a variant of the package's model).
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
import logging
import os
import threading
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import genpy
import rospy
from atlas_msgs.msg import (
    AtlasCommand,
    AtlasState,
    ControllerStatistics,
    ForceTorqueSensors,
    SynchronizationStatistics,
    Test,
)
from atlas_msgs.srv import ResetControls, ResetControlsResponse
from geometry_msgs.msg import Pose, TransformStamped, Twist, Wrench, WrenchStamped
from nav_msgs.msg import Odometry
from osrf_msgs.msg import JointCommands
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState
from std_msgs.msg import String
from std_srvs.srv import Empty, EmptyResponse
from tf2_msgs.msg import TFMessage
from trajectory_msgs.msg import JointTrajectory

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.bag_dir import unwritable_reason
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.node.master_watch import start_master_watch
from tutorial_atlas_control.node.recorder_watch import start_recorder_watch
from tutorial_atlas_control.node.transport import WireBatch, widen_accept_queue
from tutorial_atlas_control.node.udpros import serve as serve_udpros
from tutorial_atlas_control.node.viewer import ViewerLink, ViewerRequest, display_problem
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.camera import configure_viewer_camera, configure_viewer_scene
from tutorial_atlas_control.sim.controller import GainsError, gains_from_params
from tutorial_atlas_control.sim.controller_statistics import (
    DEFAULT_WINDOW_S,
    UPDATE_RATE_PARAM,
    WINDOW_PARAM,
    CommandAgeStatistics,
)
from tutorial_atlas_control.sim.joint_trajectory import TrajectoryMessage, trajectory_input
from tutorial_atlas_control.sim.link_transforms import LinkTransforms
from tutorial_atlas_control.sim.simulator import (
    DEFAULT_TIME_TO_UNPIN_S,
    AtlasSimulator,
    ModeError,
    parse_mode,
)
from tutorial_atlas_control.sim.urdf import UrdfError, matching_urdf, read_joints
from tutorial_atlas_control.sim.vrc import (
    DEFAULT_STARTUP_MODE,
    STARTUP_MODES,
    InputError,
    ModeInput,
    SimInput,
    VrcMode,
    cmd_vel_input,
    input_notes,
    parse_vrc_mode,
    pose_input,
    wrench_input,
)
from tutorial_atlas_control.stepping.loop import (
    LINKS_TF_RATE_HZ,
    ResetControlsRequest,
    SteppingLoop,
)
from tutorial_atlas_control.stepping.synchronization import DelayBudgets, SynchronizationWindow
from tutorial_atlas_control.units import finite_number

NODE_NAME = 'atlas_sim'
#: Seconds between repeats of the same refusal warning.
WARN_THROTTLE_S = 2.0
#: The viewer draws at most one frame per VIEWER_FRAME_PERIOD_S (s, wall): left alone, its
#: render thread draws as fast as it can, and with software OpenGL (no GPU, Xvfb) that took
#: the CPU the simulation needs. The pause is VIEWER_HOLD_S of it; the rest is its turn.
VIEWER_FRAME_PERIOD_S = 1.0 / 30.0
VIEWER_TURN_S = 0.005
VIEWER_HOLD_S = VIEWER_FRAME_PERIOD_S - VIEWER_TURN_S
#: Who publishes the links' transforms (~tf_publisher; the first is the default).
TF_PUBLISHERS = ('sim', 'robot_state_publisher')
#: robot_state_publisher's latched topic of the fixed joints' transforms.
TF_STATIC = '/tf_static'

#: What the stepping loop publishes through the node's publishers, with their types; /tf
#: (world -> pelvis, and the links with ~tf_publisher sim) only with ~tf.
LOOP_TOPICS = (
    (topics.CLOCK, Clock), (topics.JOINT_STATES, JointState),
    (topics.GROUND_TRUTH_ODOM, Odometry), (topics.IMU, Imu),
    (topics.L_FOOT_CONTACT, WrenchStamped), (topics.R_FOOT_CONTACT, WrenchStamped),
    (topics.CONTROLLER_STATISTICS, ControllerStatistics),
    (topics.ATLAS_STATE, AtlasState), (topics.FORCE_TORQUE_SENSORS, ForceTorqueSensors),
    (topics.DEBUG_L_FOOT_CONTACT, WrenchStamped), (topics.DEBUG_R_FOOT_CONTACT, WrenchStamped))


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


class RawLatched:
    """A pre-serialized message as rospy's latch: what a new subscriber of a latched
    publisher gets first (rospy serializes the latch with serialize_message)."""

    _has_header = False

    def __init__(self, data: bytes) -> None:
        self.data = data

    def serialize(self, buff: io.BytesIO) -> None:
        buff.write(self.data)


class RosLog:
    """The stepping loop's log lines, into rospy's log (stepping.loop.LoopLog).

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
    services, parameters and the viewer window."""

    def __init__(self, sim: AtlasSimulator, real_time_factor: float, paused: bool,
                 rates_hz: dict[str, float], gui: bool, tf: bool = False,
                 sync_budgets: DelayBudgets | None = None,
                 links: LinkTransforms | None = None) -> None:
        self.sim = sim
        self.gui = gui
        # UDPROS for roscpp's unreliable() subscribers, before the master announces a topic.
        self.udpros = serve_udpros()
        widen_accept_queue()  # a dozen subscribers connect at once when it advertises
        self._advertise(tf)
        statistics = self._controller_statistics()
        outbox = WireBatch()
        # Before rospy closes the connections: what a stalled-then-live subscriber (the
        # recorder) has not taken yet (transport.ConnectionWriter.drain).
        rospy.on_shutdown(outbox.drain)
        self.loop = SteppingLoop(sim, outbox, self.publishers, rates_hz, statistics,
                                 RosLog(), self._publish_config,
                                 real_time_factor=real_time_factor, paused=paused,
                                 publish_input=self._publish_input,
                                 synchronization=SynchronizationWindow(
                                     sync_budgets or DelayBudgets()),
                                 latch_synchronization=self._latch_synchronization,
                                 links=links if tf else None)
        if tf and links is not None:
            self._publish_static_transforms(links)
        self.loop.publish_config()
        self.mode_pub.publish(String(data=sim.mode.value))
        self._subscribe()

    def _advertise(self, tf: bool) -> None:
        """The publishers; the loop serializes their messages itself (msgs/wire.py).

        queue_size=None: plain synchronous connections, without rospy's per-message
        writer-thread handoff. A subscriber that cannot keep up slows the loop (TCP
        back-pressure) instead of losing messages; one that stops reading is not waited
        for, and is dropped once it has accepted nothing for transport.SEND_TIMEOUT_S
        (node/transport.py).
        """
        published = LOOP_TOPICS + (((topics.TF, TFMessage),) if tf else ())
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', SyntaxWarning)  # rospy: "explicit queue_size"
            self.publishers = {topic: rospy.Publisher(topic, msg_class, queue_size=None)
                               for topic, msg_class in published}
            # Latched, as DRCSim's: a new subscriber gets the latest step's delays at once.
            self.publishers[topics.SYNCHRONIZATION_STATISTICS] = rospy.Publisher(
                topics.SYNCHRONIZATION_STATISTICS, SynchronizationStatistics, queue_size=None,
                latch=True)
        # Latched, recorded in every bag: what offline replay needs to re-create the run.
        self.config_pub = rospy.Publisher(topics.SIM_CONFIG, String, queue_size=1, latch=True)
        # Each applied cheat, with the sim time it took effect: what replay re-applies.
        self.inputs_pub = rospy.Publisher(topics.SIM_INPUTS, String, queue_size=100)
        # Latched: the mode now, for traj_yaml.py's warning and `rostopic echo`.
        self.mode_pub = rospy.Publisher(topics.CURRENT_CONTROL_MODE, String, queue_size=1,
                                        latch=True)

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
        self.static_tf_pub = rospy.Publisher(TF_STATIC, TFMessage, queue_size=1, latch=True)
        self.static_tf_pub.publish(message)

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
        rospy.Subscriber(topics.CONTROL_MODE, String, self.on_control_mode, queue_size=10)
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
        self._subscribe_cheats()

    def _subscribe_cheats(self) -> None:
        """VRCPlugin's, gazebo_ros_force's and gazebo_ros_joint_trajectory's topics."""
        lower, upper = self.sim.atlas.lower_rad, self.sim.atlas.upper_rad
        links = frozenset(self.sim.vrc.link_names)
        cheats: tuple[tuple[str, type, Callable[[Any], SimInput]], ...] = (
            (topics.MODE, String, lambda msg: ModeInput(parse_vrc_mode(msg.data))),
            (topics.SET_POSE, Pose, lambda msg: pose_input(
                (msg.position.x, msg.position.y, msg.position.z),
                (msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w))),
            (topics.CMD_VEL, Twist, lambda msg: cmd_vel_input(
                (msg.linear.x, msg.linear.y, msg.linear.z),
                (msg.angular.x, msg.angular.y, msg.angular.z))),
            (topics.APPLY_PELVIS_FORCE, Wrench, lambda msg: wrench_input(
                (msg.force.x, msg.force.y, msg.force.z),
                (msg.torque.x, msg.torque.y, msg.torque.z))),
            (topics.JOINT_TRAJECTORY, JointTrajectory, lambda msg: trajectory_input(
                TrajectoryMessage.from_ros(msg), lower, upper, links)),
        )
        for topic, msg_class, decode in cheats:
            rospy.Subscriber(topic, msg_class, self._cheat_handler(topic, decode),
                             queue_size=100)
        rospy.Subscriber(topics.CONFIGURATION, JointState, self.on_configuration, queue_size=10)

    def _cheat_handler(self, topic: str,
                       decode: Callable[[Any], SimInput]) -> Callable[[Any], None]:
        """A callback that checks the message whole, then hands it to the loop."""
        def handle(msg: Any) -> None:
            try:
                item = decode(msg)
            except InputError as err:
                # Per message text: rospy's plain throttle is per call site, and would
                # hide a refusal on one topic behind another's.
                rospy.logwarn_throttle_identical(WARN_THROTTLE_S,
                                                 f'refused {topic}: {err}; nothing applied')
                return
            for note in input_notes(item):  # what the check changed, once per message
                log = rospy.logwarn if note.level >= logging.WARNING else rospy.loginfo
                log(f'{topic}: {note.text}')
            self.loop.apply_input(item)
        return handle

    @staticmethod
    def on_configuration(_msg: JointState) -> None:
        """As VRCPlugin: planned but never implemented; said once per message."""
        rospy.logerr_throttle(WARN_THROTTLE_S, f'{topics.CONFIGURATION} is not implemented '
                              '(nor was it in DRCSim); nothing applied')

    def _latch_synchronization(self, message: bytes) -> None:
        """The latest /atlas/synchronization_statistics (without its length prefix), for
        subscribers to come."""
        self.publishers[topics.SYNCHRONIZATION_STATISTICS].impl.latch = RawLatched(message)

    def _publish_input(self, text: str) -> None:
        """/atlas/sim_inputs (recorded): one applied cheat."""
        self.inputs_pub.publish(String(data=text))

    def _publish_config(self, text: str) -> None:
        """/atlas/sim_config (latched, recorded in every bag): what replay needs."""
        self.config_pub.publish(String(data=text))

    # -- subscriptions and services ----------------------------------------------------
    def on_joint_commands(self, msg: RawJointCommands) -> None:
        """Hand the raw message to the loop, which decodes it before its next step."""
        self.loop.receive_command(msg.raw)

    def on_atlas_command(self, msg: RawAtlasCommand) -> None:
        self.loop.receive_command(msg.raw, topics.ATLAS_COMMAND)

    def on_test(self, msg: RawTest) -> None:
        self.loop.receive_command(msg.raw, topics.ATLAS_TEST)

    def on_reset_controls(self, request: ResetControls._request_class
                          ) -> ResetControlsResponse:
        """atlas_msgs/ResetControls: the loop checks and applies it (stepping/loop.py)."""
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
        previous = self.loop.set_mode(mode)
        self.mode_pub.publish(String(data=mode.value))
        rospy.loginfo(f'control mode: {previous.value} -> {mode.value}')

    def _service(self, action: Callable[[], None]) -> Callable[[object], EmptyResponse]:
        def handle(_request: object) -> EmptyResponse:
            action()
            return EmptyResponse()
        return handle

    # -- the loop ------------------------------------------------------------------------
    def spin(self) -> int:
        """Run the stepping loop until ROS shuts down (with the viewer, if asked); the exit
        status."""
        viewer = self._open_viewer() if self.gui else None
        # One line if the recorder goes (killed, disk full) while the simulation goes on;
        # registered again with a restarted master.
        watch = start_recorder_watch(self.publishers[topics.JOINT_STATES],
                                     lambda: self.sim.sim_time_ns * 1e-9, time.monotonic)
        start_master_watch(watch)
        status = self.loop.run(rospy.is_shutdown)
        watch.set()
        if status:
            rospy.signal_shutdown('physics diverges after every reset')
        if viewer is not None:
            viewer.close()
        return status

    # -- the viewer ----------------------------------------------------------------------
    def _open_viewer(self) -> ViewerLink | None:
        """The viewer window, framing the whole robot and following the pelvis, kept up to
        date by a thread of its own (_viewer_loop)."""
        problem = display_problem(os.environ.get('DISPLAY'))
        if problem is not None:
            rospy.logwarn(f'cannot open the MuJoCo viewer: {problem}; running headless, '
                          'recording on (gui:=false starts without trying)')
            return None
        try:
            link = ViewerLink(self.sim.model)
        except Exception as err:  # noqa: BLE001 - no display, no GL: run headless
            rospy.logwarn(f'cannot open the MuJoCo viewer ({err}); running headless')
            return None
        with self.loop.lock:
            link.copy_in(self.sim.data)
        with link.handle.lock():
            configure_viewer_camera(link.handle.cam, self.sim.model, link.shadow)
            configure_viewer_scene(link.handle.user_scn)
        threading.Thread(target=self._viewer_loop, args=(link,), name='viewer',
                         daemon=True).start()
        return link

    def _viewer_loop(self, viewer: ViewerLink) -> None:
        """Refresh the window and pace its drawing, outside the stepping loop."""
        while not rospy.is_shutdown() and self._update_viewer(viewer):
            viewer.hold(VIEWER_HOLD_S)  # its render thread waits at the top of its next frame
            time.sleep(VIEWER_TURN_S)

    def _update_viewer(self, viewer: ViewerLink) -> bool:
        """Refresh the window and carry out what was asked in it; False once it is closed.

        The lock is held only to copy the state in and the mouse forces out: the sync
        itself waits for the viewer's thread, which must not stall services and commands.
        """
        if not viewer.is_running():
            rospy.signal_shutdown('viewer closed')
            return False
        loop = self.loop
        with loop.lock:
            viewer.copy_in(self.sim.data)
        viewer.sync()
        with loop.lock:
            viewer.copy_out(self.sim.data)
        for request in viewer.take_requests():
            if request is ViewerRequest.RESET_WORLD:
                loop.reset_world(by=' (viewer)')
            elif loop.paused:  # ViewerRequest.TOGGLE_PAUSE
                loop.unpause()
            else:
                loop.pause()
        viewer.show_paused(loop.paused)
        return True


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
    rates_hz = {
        'joint_states': _float_param('~joint_states_rate', 1000.0),
        'odom': _float_param('~odom_rate', 100.0),
        'imu': _float_param('~imu_rate', 1000.0),
        'contact': _float_param('~contact_rate', 1000.0),
        'tf': _float_param('~tf_rate', 100.0),
        'atlas_state': _float_param('~atlas_state_rate', 1000.0),
        'force_torque_sensors': _float_param('~force_torque_sensors_rate', 1000.0),
        'debug_contact': _float_param('~debug_contact_rate', 1000.0),
        'links_tf': _float_param('~links_tf_rate', LINKS_TF_RATE_HZ, minimum=1.0),
    }
    tf_publisher = rospy.get_param('~tf_publisher', TF_PUBLISHERS[0])
    if tf_publisher not in TF_PUBLISHERS:
        raise AtlasControlError(f'parameter {rospy.resolve_name("~tf_publisher")} must be one '
                                f'of {", ".join(TF_PUBLISHERS)}, got {tf_publisher!r}')
    model_file = rospy.get_param('~model_file', str(atlas_model.MODEL_PATH))
    if not isinstance(model_file, str) or not model_file:
        raise AtlasControlError(f'parameter {rospy.resolve_name("~model_file")} must be the '
                                f'path of an MJCF file, got {model_file!r}')
    startup_mode = rospy.get_param(topics.STARTUP_MODE_PARAM, DEFAULT_STARTUP_MODE.value)
    if startup_mode not in STARTUP_MODES:
        raise AtlasControlError(f'parameter {topics.STARTUP_MODE_PARAM} must be one of '
                                f'{", ".join(STARTUP_MODES)}, got {startup_mode!r}')
    sim = AtlasSimulator(atlas_model.load_model(Path(model_file)), gains, time_to_unpin_s,
                         startup_mode=VrcMode(startup_mode))
    description = _tf_wanted(Path(model_file), sim)
    return SimNode(sim, _float_param('~real_time_factor', 1.0),
                   bool(rospy.get_param('~paused', False)), rates_hz,
                   bool(rospy.get_param('~gui', False)), description is not None,
                   DelayBudgets.from_params(rospy.get_param),
                   _links_publisher(description) if tf_publisher == 'sim' else None)


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
