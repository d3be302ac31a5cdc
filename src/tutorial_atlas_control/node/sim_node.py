"""The simulator node: AtlasSimulator behind DRCSim's ROS interface.

Thin ROS glue. Publishes /clock, /atlas/joint_states, /ground_truth_odom, /atlas/imu and
the foot contact wrenches in sim time, /atlas/controller_statistics (command age, while
subscribed), and a latched /atlas/sim_config (JSON: timestep, time_to_unpin, model file and
checksum, time of the last reset) for offline replay; obeys
/atlas/joint_commands and /atlas/control_mode; offers gazebo_ros's reset and pause services.

Parameters (private unless noted):
    ~real_time_factor (float, 1.0): sim time per wall time; 0 runs as fast as possible.
    ~paused (bool, false): start with physics paused (/gazebo/unpause_physics starts it).
    ~gui (bool, false): open the MuJoCo viewer (needs a display); its Reset button and key
        (Backspace) and Shift+Ctrl+R do reset_world, Space pauses/unpauses (viewer.py).
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

import collections
import sys
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

from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control import topics
from tutorial_atlas_control.msgs.commands import CommandDecoder, CommandError
from tutorial_atlas_control.sim.controller import gains_from_params
from tutorial_atlas_control.sim.controller_statistics import (
    DEFAULT_WINDOW_S, UPDATE_RATE_PARAM, WINDOW_PARAM, CommandAgeStatistics)
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.bags.render import configure_viewer_camera, configure_viewer_scene
from tutorial_atlas_control.msgs.ros1_fields import FieldCursor
from tutorial_atlas_control.msgs.sim_messages import SimMessages
from tutorial_atlas_control.sim.simulator import (
    DEFAULT_TIME_TO_UNPIN_S, AtlasSimulator, ModeError, PhysicsDivergenceError, parse_mode)
from tutorial_atlas_control.units import NS_PER_S, finite_number
from tutorial_atlas_control.sim.urdf import UrdfError, matching_urdf
from tutorial_atlas_control.node.viewer import ViewerLink, ViewerRequest
from tutorial_atlas_control.msgs.wire import (
    ControllerStatisticsWire, WireBatch, clock_bytes)

NODE_NAME = 'atlas_sim'
#: Seconds between repeats of the same refusal warning.
WARN_THROTTLE_S = 2.0
#: When the loop falls further behind wall time than this, it stops trying to catch up.
#: Below it, the loop runs flat out (sending in batches) until it is back on schedule,
#: so a loaded machine's short stalls cost no sim time.
MAX_LAG_S = 1.0
#: A divergence this soon (s of sim time) after the previous one's reset is "in a row";
#: that many in a row means the model itself is unstable and the node stops.
DIVERGENCE_REPEAT_S = 1.0
MAX_DIVERGENCES_IN_A_ROW = 3
#: Commands waiting for the next step, at most (a second of 10 kHz of them).
MAX_PENDING_COMMANDS = 10_000
#: The viewer draws at most one frame per VIEWER_FRAME_PERIOD_S (s, wall): left alone, its
#: render thread draws as fast as it can, and with software OpenGL (no GPU, Xvfb) that took
#: the CPU the simulation needs. The pause is VIEWER_HOLD_S of it; the rest is its turn.
VIEWER_FRAME_PERIOD_S = 1.0 / 30.0
VIEWER_TURN_S = 0.005
VIEWER_HOLD_S = VIEWER_FRAME_PERIOD_S - VIEWER_TURN_S
#: At real_time_factor 0 the loop sends what it published at most this often (s, wall);
#: paced runs send after every step while on schedule. Each send is a syscall per topic and
#: subscriber and a wake-up of each subscriber: at 4 ms they cost a fraction of a physics
#: step, and /clock still advances 250 times a wall second.
FLUSH_PERIOD_S = 0.004
#: A paced run more than CATCH_UP_LAG_S behind wall time sends at most every
#: CATCH_UP_FLUSH_PERIOD_S (s, wall) until it has caught up: each send is a syscall per topic
#: and subscriber, and on a loaded machine those syscalls are what keeps it behind.
CATCH_UP_LAG_S = 0.005
CATCH_UP_FLUSH_PERIOD_S = 0.004


def steps_between(rate_hz: float, dt_s: float) -> int:
    """Publish every N steps for `rate_hz`; 0 or a rate at/above the step rate = every step."""
    if rate_hz <= 0.0 or rate_hz * dt_s >= 1.0:
        return 1
    return max(1, int(round(1.0 / (rate_hz * dt_s))))


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


class SimNode:
    """Owns the simulator, its lock, the publishers and the stepping loop."""

    def __init__(self, sim: AtlasSimulator, real_time_factor: float, paused: bool,
                 rates_hz: dict[str, float], gui: bool, tf: bool = False) -> None:
        self.sim = sim
        self.lock = threading.Lock()
        self.real_time_factor = real_time_factor
        self.paused = paused
        dt_s = sim.dt_s
        self.every = {topic: steps_between(rate, dt_s) for topic, rate in rates_hz.items()}
        self.step_count = 0
        self.gui = gui
        self.exit_status = 0
        self._divergences_in_a_row = 0
        self._last_divergence_ns: int | None = None

        self._advertise(tf)
        self.batch = WireBatch()
        self._publish_config()

        # What each message holds is sim_messages' (shared with offline runs).
        self.messages = messages = SimMessages(sim)
        # The per-step messages: (every how many steps, name in SimMessages.step_wires,
        # publisher, stamped at the step's end (True) or, as poses and sensors, at its start).
        step_messages = (
            (self.every['joint_states'], 'joint_state', self.joint_state_pub, True),
            (self.every['imu'], 'imu', self.imu_pub, False),
            (self.every['contact'], 'l', self.l_contact_pub, False),
            (self.every['contact'], 'r', self.r_contact_pub, False))
        # Those due at the same steps are filled by one plan (at the launch's rates, all).
        due_together: dict[int, list[str]] = {}
        for every, name, _, _ in step_messages:
            due_together.setdefault(every, []).append(name)
        self.fill_plans = tuple((every, messages.fill_plan(names))
                                for every, names in due_together.items())
        self.step_wires = tuple((every, messages.step_wires[name], pub, at_end)
                                for every, name, pub, at_end in step_messages)
        self._init_controller_statistics()

        # Commands wait here, undecoded, for the loop (see on_joint_commands). Bounded, so
        # that a stalled loop cannot make it grow without limit; emptied every step.
        self.decoder = CommandDecoder()
        self.pending_commands: collections.deque[bytes] = collections.deque(
            maxlen=MAX_PENDING_COMMANDS)
        self._subscribe()

    def _advertise(self, tf: bool) -> None:
        """The publishers; the loop serializes their messages itself (wire.py).

        queue_size=None: plain synchronous connections, without rospy's per-message
        writer-thread handoff. A subscriber that cannot keep up slows the loop (TCP
        back-pressure) instead of losing messages, until it has accepted nothing for
        wire.SEND_TIMEOUT_S and is dropped.
        """
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', SyntaxWarning)  # rospy: "explicit queue_size"
            self.clock_pub = rospy.Publisher(topics.CLOCK, Clock, queue_size=None)
            self.joint_state_pub = rospy.Publisher(topics.JOINT_STATES, JointState,
                                                   queue_size=None)
            self.odom_pub = rospy.Publisher(topics.GROUND_TRUTH_ODOM, Odometry, queue_size=None)
            self.imu_pub = rospy.Publisher(topics.IMU, Imu, queue_size=None)
            self.l_contact_pub = rospy.Publisher(topics.L_FOOT_CONTACT, WrenchStamped,
                                                 queue_size=None)
            self.r_contact_pub = rospy.Publisher(topics.R_FOOT_CONTACT, WrenchStamped,
                                                 queue_size=None)
            # world -> pelvis; robot_state_publisher adds the links from the joint states.
            self.tf_pub = rospy.Publisher(topics.TF, TFMessage, queue_size=None) if tf else None
        # Latched, recorded in every bag: what offline replay needs to re-create the run.
        self.config_pub = rospy.Publisher(topics.SIM_CONFIG, String, queue_size=1, latch=True)

    def _subscribe(self) -> None:
        """The command and mode subscriptions and gazebo_ros's services."""
        rospy.Subscriber(topics.JOINT_COMMANDS, RawJointCommands, self.on_joint_commands,
                         queue_size=10, tcp_nodelay=True)
        rospy.Subscriber(topics.CONTROL_MODE, String, self.on_control_mode, queue_size=10)
        self.services = [
            rospy.Service(topics.RESET_WORLD_SERVICE, Empty, self._service(self.reset_world)),
            rospy.Service(topics.RESET_SIMULATION_SERVICE, Empty,
                          self._service(self.reset_simulation)),
            rospy.Service(topics.PAUSE_PHYSICS_SERVICE, Empty, self._service(self.pause)),
            rospy.Service(topics.UNPAUSE_PHYSICS_SERVICE, Empty, self._service(self.unpause)),
        ]

    def _publish_config(self) -> None:
        """(Re-)publish /atlas/sim_config: at start and after every reset."""
        self.config_pub.publish(String(data=self.sim.config().to_json()))

    # -- subscriptions and services ----------------------------------------------------
    def on_joint_commands(self, msg: RawJointCommands) -> None:
        """Queue the raw message for the loop, which decodes it before its next step.

        Nothing else happens in rospy's receiving thread: decoding there would make several
        fast publishers' threads and the loop fight over the GIL.
        """
        self.pending_commands.append(msg.raw)

    def _apply_pending_commands(self) -> None:
        """Decode, check and merge the commands received since the last step, in order.

        Newest first: a valid command for every field of every joint overwrites all that
        came before it, so the older ones in this step are dropped undecoded (DRCSim, too,
        applied only the latest command at each step). Controllers send such complete
        commands, so a flood costs one decode per step, not one per message.
        """
        pending = self.pending_commands
        raws = []
        while pending:
            raws.append(pending.popleft())
        updates = []
        for raw in reversed(raws):
            try:
                update = self.decoder.decode(raw)
            except CommandError as err:
                rospy.logwarn_throttle(
                    WARN_THROTTLE_S, f'refused /atlas/joint_commands: {err}; previous command kept')
                continue
            if not updates:
                self._note_command_stamp(raw)  # the newest applied command
            updates.append(update)
            if update.is_complete:
                break
        if not updates:
            return
        updates.reverse()
        first = self.sim.user_command is None
        self.sim.receive_updates(updates)
        if first:
            # Which command a trajectory started from: a late one makes the robot jump.
            rospy.loginfo(f'first /atlas/joint_commands since the start or last reset, at '
                          f't={self.sim.sim_time_ns / NS_PER_S:.3f} s ({self.sim.mode.value} mode)')

    def on_control_mode(self, msg: String) -> None:
        try:
            mode = parse_mode(msg.data)
        except ModeError as err:
            rospy.logwarn_throttle(WARN_THROTTLE_S, f'refused /atlas/control_mode: {err}')
            return
        with self.lock:
            previous = self.sim.mode
            self.sim.set_mode(mode)
        rospy.loginfo(f'control mode: {previous.value} -> {mode.value}')

    def _service(self, action: Callable[[], None]) -> Callable[[object], EmptyResponse]:
        def handle(_request: object) -> EmptyResponse:
            action()
            return EmptyResponse()
        return handle

    def reset_world(self) -> None:
        with self.lock:
            self.sim.reset_world()
        self._publish_config()
        rospy.loginfo('reset_world: robot back to its initial pose (torso pinned '
                      f'for {self.sim.time_to_unpin_s} s)')

    def reset_simulation(self) -> None:
        with self.lock:
            self.sim.reset_simulation()
            self.statistics.forget_command()  # its stamp lies in the rewound future
        self._publish_config()
        rospy.loginfo('reset_simulation: robot reset and sim time back to 0')

    def pause(self) -> None:
        self.paused = True
        rospy.loginfo('physics paused')

    def unpause(self) -> None:
        self.paused = False
        rospy.loginfo('physics unpaused')

    # -- publishing ----------------------------------------------------------------------
    def publish(self) -> None:
        """Serialize what is due this step into the batch (called under the lock)."""
        sim = self.sim
        now_ns = sim.sim_time_ns
        batch = self.batch
        wanted = batch.wanted
        if wanted(self.clock_pub):
            # Only the latest time goes out per flush: every step when paced, about one
            # per FLUSH_PERIOD_S of wall time at real_time_factor 0 (what a sim-time timer
            # sees at real time); spares the recorder one message in five.
            batch.replace(self.clock_pub, clock_bytes(now_ns))
        count = self.step_count
        for every, plan in self.fill_plans:
            if count % every == 0:
                plan()
        # Poses and sensors describe the state at the start of the last step (see step()).
        sensed_ns = sim.state_time_ns
        for every, message, pub, at_end in self.step_wires:
            if count % every == 0 and wanted(pub):
                batch.add(pub, message.stamped(now_ns if at_end else sensed_ns))
        messages = self.messages
        if count % self.every['odom'] == 0 and wanted(self.odom_pub):
            batch.add(self.odom_pub, messages.odometry(sensed_ns))
        if self.tf_pub is not None and count % self.every['tf'] == 0 and wanted(self.tf_pub):
            batch.add(self.tf_pub, messages.pelvis_tf(sensed_ns))

    # -- /atlas/controller_statistics ----------------------------------------------------
    def _init_controller_statistics(self) -> None:
        """DRCSim's command age statistics, fed and published only while subscribed."""
        rate_hz = rospy.get_param(UPDATE_RATE_PARAM) if rospy.has_param(UPDATE_RATE_PARAM) else None
        self.statistics = CommandAgeStatistics(
            self.sim.dt_s, rospy.get_param(WINDOW_PARAM, DEFAULT_WINDOW_S), rate_hz)
        self.statistics_msg = ControllerStatisticsWire()
        with warnings.catch_warnings():
            warnings.simplefilter('ignore', SyntaxWarning)  # rospy: "explicit queue_size"
            self.statistics_pub = rospy.Publisher(topics.CONTROLLER_STATISTICS,
                                                  ControllerStatistics, queue_size=None)

    def _note_command_stamp(self, raw: bytes) -> None:
        """The command in `raw` is applied from the coming step on: remember its stamp."""
        self.statistics.command_applied(FieldCursor(raw).header_stamp_ns(),
                                        self.sim.sim_time_ns + self.sim.step_ns)

    def _publish_controller_statistics(self, now_ns: int) -> None:
        """After each step: the command age at `now_ns`, into the window and, when due, out."""
        if not self.batch.wanted(self.statistics_pub):
            return
        stats = self.statistics
        stats.update(now_ns)
        if stats.publication_due(now_ns):
            self.statistics_msg.set_values(stats.age_s, stats.mean_s, stats.variance_s2,
                                           stats.window_s)
            self.batch.add(self.statistics_pub, self.statistics_msg.stamped(now_ns))

    # -- the loop ------------------------------------------------------------------------
    def spin(self) -> None:
        """Step, publish and pace against wall time until ROS shuts down."""
        viewer = self._open_viewer() if self.gui else None
        wall0 = time.perf_counter()
        sim0_ns = self.sim.sim_time_ns
        with self.lock:
            self.publish()  # /clock and the initial state before the first step
        self.batch.flush()
        last_flush_s = time.perf_counter()
        while not rospy.is_shutdown():
            if self.paused:
                with self.lock:
                    self._apply_pending_commands()
                self.batch.flush()
                time.sleep(0.01)
                wall0, sim0_ns = time.perf_counter(), self.sim.sim_time_ns
                continue
            with self.lock:
                self._apply_pending_commands()
                try:
                    self.sim.step()
                except PhysicsDivergenceError as err:
                    if not self._recover(err):
                        break
                self.step_count += 1
                self.publish()
                self._publish_controller_statistics(self.sim.sim_time_ns)
                sim_ns = self.sim.sim_time_ns
            if sim_ns < sim0_ns:  # reset_simulation rewound time
                wall0, sim0_ns = time.perf_counter(), sim_ns
            # Send outside the lock: after every step while paced and less than
            # CATCH_UP_LAG_S behind; else (unpaced, or catching up) about every flush period:
            # TCPROS is a byte stream, one sendall carries many messages, and the syscalls
            # saved are what lets a loaded simulator catch up.
            now_s = time.perf_counter()
            if self.real_time_factor > 0.0:
                due_s = wall0 + (sim_ns - sim0_ns) / NS_PER_S / self.real_time_factor
                flush = (now_s - due_s < CATCH_UP_LAG_S
                         or now_s - last_flush_s >= CATCH_UP_FLUSH_PERIOD_S)
            else:
                flush = now_s - last_flush_s >= FLUSH_PERIOD_S
            if flush:
                self.batch.flush()
                last_flush_s = now_s
            if self.real_time_factor > 0.0:
                due_s = wall0 + (sim_ns - sim0_ns) / NS_PER_S / self.real_time_factor
                ahead_s = due_s - time.perf_counter()
                if ahead_s > 0.0:
                    time.sleep(ahead_s)
                elif ahead_s < -MAX_LAG_S:
                    wall0, sim0_ns = time.perf_counter(), sim_ns
        if viewer is not None:
            viewer.close()

    def _recover(self, err: PhysicsDivergenceError) -> bool:
        """Log a divergence and reset the robot; False (stop) when the model keeps diverging."""
        now_ns = self.sim.sim_time_ns
        last_ns = self._last_divergence_ns
        if last_ns is not None and 0 <= now_ns - last_ns <= DIVERGENCE_REPEAT_S * NS_PER_S:
            self._divergences_in_a_row += 1
        else:
            self._divergences_in_a_row = 1
        self._last_divergence_ns = now_ns
        if self._divergences_in_a_row >= MAX_DIVERGENCES_IN_A_ROW:
            rospy.logfatal(f'{err}: {MAX_DIVERGENCES_IN_A_ROW} times in a row, each within '
                           f'{DIVERGENCE_REPEAT_S} s of the reset; the model '
                           f'{self.sim.atlas_path} is unstable; stopping the simulator')
            self.exit_status = 1
            rospy.signal_shutdown('physics diverges after every reset')
            return False
        rospy.logerr(f'{err}; resetting the robot to its initial state')
        self.sim.reset_world()
        self._publish_config()
        return True

    def _open_viewer(self) -> ViewerLink | None:
        """The viewer window, framing the whole robot and following the pelvis, kept up to
        date by a thread of its own (_viewer_loop)."""
        try:
            link = ViewerLink(self.sim.model)
        except Exception as err:  # noqa: BLE001 - no display, no GL: run headless
            rospy.logwarn(f'cannot open the MuJoCo viewer ({err}); running headless')
            return None
        with self.lock:
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
        with self.lock:
            viewer.copy_in(self.sim.data)
        viewer.sync()
        with self.lock:
            viewer.copy_out(self.sim.data)
        for request in viewer.take_requests():
            if request is ViewerRequest.RESET_WORLD:
                rospy.loginfo('viewer: Reset -> reset_world')
                self.reset_world()
            elif self.paused:  # ViewerRequest.TOGGLE_PAUSE
                self.unpause()
            else:
                self.pause()
        viewer.show_paused(self.paused)
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


def main(argv: list[str] | None = None) -> int:
    """Entry point of sim/atlas_sim_node.py."""
    args = rospy.myargv(argv if argv is not None else sys.argv)
    if len(args) > 1 and args[1] in ('-h', '--help'):
        print(__doc__)
        return 0
    rospy.init_node(NODE_NAME)
    try:
        node = build_node()
    except AtlasControlError as err:
        rospy.logfatal(f'{NODE_NAME}: {err}')
        return 1
    rospy.loginfo(f'Atlas v1 simulator ready: dt={node.sim.dt_s * 1000:.1f} ms, '
                  f'real_time_factor={node.real_time_factor}, paused={node.paused}, '
                  f'torso pinned for {node.sim.time_to_unpin_s} s')
    node.spin()
    return node.exit_status
