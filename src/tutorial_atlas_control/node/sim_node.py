"""The simulator node: AtlasSimulator behind DRCSim's ROS interface.

The rospy shell around the stepping loop (stepping/loop.py, no ROS): publishers,
subscriptions, services, parameters and the viewer window. Publishes /clock,
/atlas/joint_states, /ground_truth_odom, /atlas/imu and the foot contact wrenches in sim
time, /atlas/controller_statistics (command age, while subscribed), and a latched
/atlas/sim_config (JSON: timestep, time_to_unpin, model file and checksum, time of the last
reset) for offline replay, and a latched /atlas/current_control_mode (the mode now); obeys
/atlas/joint_commands and /atlas/control_mode; offers gazebo_ros's reset and pause services.
Logs one line per fall (pelvis below 0.5 m, once until a reset) and per reset, and warns
when commands arrive in a mode that does not apply them.

Parameters (private unless noted):
    ~real_time_factor (float, 1.0): sim time per wall time; 0 runs as fast as possible.
    ~paused (bool, false): start with physics paused (/gazebo/unpause_physics starts it).
    ~gui (bool, false): open the MuJoCo viewer (needs a display; a $DISPLAY no X server
        answers gives one warning and a headless run); its Reset button and key (Backspace)
        and Shift+Ctrl+R do reset_world, Space pauses/unpauses (viewer.py).
    ~joint_states_rate, ~imu_rate, ~contact_rate (Hz, 1000): 0 or >= 1000 = every step.
    ~odom_rate (Hz, 100): /ground_truth_odom rate, as DRCSim.
    ~tf (bool, true): broadcast world -> pelvis on /tf from the ground truth, if the model
        has a matching URDF (urdf.matching_urdf); else one warning and no /tf.
    ~tf_rate (Hz, 100): /tf rate.
    ~model_file (str, the package's sim/atlas_v1.xml): the MJCF to simulate; it must have
        Atlas v1's joints, actuators and sensors (a variant of the package's model).
    /atlas/time_to_unpin (float, 1.0): seconds the torso stays pinned after start/reset.
    atlas_controller/gains/<joint>/{p,i,d,i_clamp}: the gains Stand/Freeze/User-hold use.
    atlas_controller/statistics_time_window_size (s, 1.0): window of the command age statistics.
    /atlas/controller_statistics/update_rate (Hz, unset = every step): clamped to 1..10000.
"""

from __future__ import annotations

import os
import threading
import time
import warnings
from collections.abc import Callable
from pathlib import Path

import genpy
import rospy
from atlas_msgs.msg import ControllerStatistics
from geometry_msgs.msg import WrenchStamped
from nav_msgs.msg import Odometry
from osrf_msgs.msg import JointCommands
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, JointState
from std_msgs.msg import String
from std_srvs.srv import Empty, EmptyResponse
from tf2_msgs.msg import TFMessage

from tutorial_atlas_control import topics
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.node.transport import WireBatch
from tutorial_atlas_control.node.viewer import ViewerLink, ViewerRequest, display_problem
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.camera import configure_viewer_camera, configure_viewer_scene
from tutorial_atlas_control.sim.controller import gains_from_params
from tutorial_atlas_control.sim.controller_statistics import (
    DEFAULT_WINDOW_S,
    UPDATE_RATE_PARAM,
    WINDOW_PARAM,
    CommandAgeStatistics,
)
from tutorial_atlas_control.sim.simulator import (
    DEFAULT_TIME_TO_UNPIN_S,
    AtlasSimulator,
    ModeError,
    parse_mode,
)
from tutorial_atlas_control.sim.urdf import UrdfError, matching_urdf
from tutorial_atlas_control.stepping.loop import SteppingLoop
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
#: What the stepping loop publishes through the node's publishers, with their types; /tf
#: (world -> pelvis; robot_state_publisher adds the links) only with ~tf.
LOOP_TOPICS = (
    (topics.CLOCK, Clock), (topics.JOINT_STATES, JointState),
    (topics.GROUND_TRUTH_ODOM, Odometry), (topics.IMU, Imu),
    (topics.L_FOOT_CONTACT, WrenchStamped), (topics.R_FOOT_CONTACT, WrenchStamped),
    (topics.CONTROLLER_STATISTICS, ControllerStatistics))


class RawJointCommands(genpy.Message):
    """osrf_msgs/JointCommands as it arrives, left undecoded by rospy.

    genpy's decoder would run in the receiving thread, under the GIL the stepping loop
    needs, and at thousands of commands a second starve the loop. This class keeps the real
    type, MD5 and definition, so the subscription is registered, negotiated and shown as
    osrf_msgs/JointCommands; the loop decodes `raw` itself with commands.CommandDecoder.
    """

    _type = JointCommands._type
    _md5sum = JointCommands._md5sum
    _full_text = JointCommands._full_text
    _has_header = True
    __slots__ = ['raw']

    def __init__(self) -> None:
        self.raw = b''

    def deserialize(self, str: bytes) -> RawJointCommands:  # noqa: A002 - genpy's name
        self.raw = str
        return self


class RosLog:
    """The stepping loop's log lines, into rospy's log (stepping.loop.LoopLog)."""

    @staticmethod
    def info(text: str) -> None:
        rospy.loginfo(text)

    @staticmethod
    def warn(text: str) -> None:
        rospy.logwarn(text)

    @staticmethod
    def refused_command(text: str) -> None:
        rospy.logwarn_throttle(WARN_THROTTLE_S, text)

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
                 rates_hz: dict[str, float], gui: bool, tf: bool = False) -> None:
        self.sim = sim
        self.gui = gui
        self._advertise(tf)
        statistics = self._controller_statistics()
        self.loop = SteppingLoop(sim, WireBatch(), self.publishers, rates_hz, statistics,
                                 RosLog(), self._publish_config,
                                 real_time_factor=real_time_factor, paused=paused)
        self.loop.publish_config()
        self.mode_pub.publish(String(data=sim.mode.value))
        self._subscribe()

    def _advertise(self, tf: bool) -> None:
        """The publishers; the loop serializes their messages itself (msgs/wire.py).

        queue_size=None: plain synchronous connections, without rospy's per-message
        writer-thread handoff. A subscriber that cannot keep up slows the loop (TCP
        back-pressure) instead of losing messages, until it has accepted nothing for
        transport.SEND_TIMEOUT_S and is dropped.
        """
        published = LOOP_TOPICS + (((topics.TF, TFMessage),) if tf else ())
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', SyntaxWarning)  # rospy: "explicit queue_size"
            self.publishers = {topic: rospy.Publisher(topic, msg_class, queue_size=None)
                               for topic, msg_class in published}
        # Latched, recorded in every bag: what offline replay needs to re-create the run.
        self.config_pub = rospy.Publisher(topics.SIM_CONFIG, String, queue_size=1, latch=True)
        # Latched: the mode now, for traj_yaml.py's warning and `rostopic echo`.
        self.mode_pub = rospy.Publisher(topics.CURRENT_CONTROL_MODE, String, queue_size=1,
                                        latch=True)

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
        rospy.Subscriber(topics.CONTROL_MODE, String, self.on_control_mode, queue_size=10)
        loop = self.loop
        self.services = [
            rospy.Service(topics.RESET_WORLD_SERVICE, Empty, self._service(loop.reset_world)),
            rospy.Service(topics.RESET_SIMULATION_SERVICE, Empty,
                          self._service(loop.reset_simulation)),
            rospy.Service(topics.PAUSE_PHYSICS_SERVICE, Empty, self._service(loop.pause)),
            rospy.Service(topics.UNPAUSE_PHYSICS_SERVICE, Empty, self._service(loop.unpause)),
        ]

    def _publish_config(self, text: str) -> None:
        """/atlas/sim_config (latched, recorded in every bag): what replay needs."""
        self.config_pub.publish(String(data=text))

    # -- subscriptions and services ----------------------------------------------------
    def on_joint_commands(self, msg: RawJointCommands) -> None:
        """Hand the raw message to the loop, which decodes it before its next step."""
        self.loop.receive_command(msg.raw)

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
        status = self.loop.run(rospy.is_shutdown)
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
    gains = gains_from_params(rospy.get_param(topics.GAINS_PARAM, {}))
    time_to_unpin_s = _float_param(topics.TIME_TO_UNPIN_PARAM, DEFAULT_TIME_TO_UNPIN_S)
    rates_hz = {
        'joint_states': _float_param('~joint_states_rate', 1000.0),
        'odom': _float_param('~odom_rate', 100.0),
        'imu': _float_param('~imu_rate', 1000.0),
        'contact': _float_param('~contact_rate', 1000.0),
        'tf': _float_param('~tf_rate', 100.0),
    }
    model_file = rospy.get_param('~model_file', str(atlas_model.MODEL_PATH))
    if not isinstance(model_file, str) or not model_file:
        raise AtlasControlError(f'parameter {rospy.resolve_name("~model_file")} must be the '
                                f'path of an MJCF file, got {model_file!r}')
    sim = AtlasSimulator(atlas_model.load_model(Path(model_file)), gains, time_to_unpin_s)
    return SimNode(sim, _float_param('~real_time_factor', 1.0),
                   bool(rospy.get_param('~paused', False)), rates_hz,
                   bool(rospy.get_param('~gui', False)), _tf_wanted(Path(model_file), sim))


def _tf_wanted(model_file: Path, sim: AtlasSimulator) -> bool:
    """~tf, unless the model has no matching URDF: then one warning saying why."""
    if not rospy.get_param('~tf', True):
        return False
    try:
        matching_urdf(model_file, sim.model)
    except UrdfError as err:
        rospy.logwarn(f'TF is off: {err}; rviz cannot show this model '
                      '(write a matching URDF beside it to get TF)')
        return False
    return True
