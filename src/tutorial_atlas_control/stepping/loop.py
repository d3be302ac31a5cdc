"""The simulator node's stepping loop, without ROS.

Each turn: merge the commands that arrived since the last step, step, serialize what is
due into the outbox, decide whether to send it, and wait for wall time. The loop also owns
what the node's services and viewer do to the simulator (resets, pause, control mode),
under the lock that rospy's threads and the viewer's share with it.
Headless, its log lines are what the user sees of a run: one per fall (pelvis below
FALL_HEIGHT_M, once until a reset), one per reset, and a warning when commands arrive in a
mode that does not apply them.

The node (node/sim_node.py) gives it an Outbox (rospy publishers behind
transport.WireBatch), a LoopLog (rospy's log) and its shutdown test; tests give it fakes.
"""

from __future__ import annotations

import collections
import threading
from collections.abc import Callable, Hashable, Mapping
from dataclasses import dataclass
from typing import Protocol

from tutorial_atlas_control import topics
from tutorial_atlas_control.command.arrays import (
    FIELD_NAMES,
    LAW_FIELDS,
    CommandError,
    CommandUpdate,
)
from tutorial_atlas_control.fall_report import fall_line
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.msgs.atlas_command import (
    AtlasUpdate,
    decode_atlas_command,
    decode_test,
)
from tutorial_atlas_control.msgs.joint_commands import CommandDecoder
from tutorial_atlas_control.msgs.ros1_fields import FieldCursor
from tutorial_atlas_control.msgs.wire import ControllerStatisticsWire, clock_bytes
from tutorial_atlas_control.sim.controller import Gains
from tutorial_atlas_control.sim.controller_statistics import CommandAgeStatistics
from tutorial_atlas_control.sim.link_transforms import LinkTransforms, RspSchedule
from tutorial_atlas_control.sim.model import FALL_HEIGHT_M
from tutorial_atlas_control.sim.sim_messages import SimMessages
from tutorial_atlas_control.sim.simulator import AtlasSimulator, ControlMode, PhysicsDivergenceError
from tutorial_atlas_control.sim.vrc import SimInput, describe_input
from tutorial_atlas_control.stepping.pacing import Pacer
from tutorial_atlas_control.stepping.schedule import STAMPED_AT_STEP_END, steps_between
from tutorial_atlas_control.stepping.synchronization import (
    DelayBudgets,
    DelayReport,
    SynchronizationWindow,
    SyncOutcome,
    is_fresh,
    statistics_bytes,
)
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['MAX_PENDING_COMMANDS', 'ON_DEMAND_MESSAGES', 'DivergenceGuard', 'LoopLog', 'Outbox',
           'ResetControlsRequest', 'SteppingLoop']

#: A divergence this soon (s of sim time) after the previous one's reset is "in a row";
#: that many in a row means the model itself is unstable and the loop stops.
DIVERGENCE_REPEAT_S = 1.0
MAX_DIVERGENCES_IN_A_ROW = 3
#: Commands waiting for the next step, at most (a second of 10 kHz of them).
MAX_PENDING_COMMANDS = 10_000
#: An applied input of a kind is logged at most once per this much sim time (s): a
#: disturbance generator streaming a wrench at 1 kHz must not flood /rosout.
INPUT_LOG_PERIOD_S = 1.0
#: Commands arriving while the mode is not User are warned about at once, then at most
#: this often (s of sim time) while they keep coming.
NOT_USER_WARN_PERIOD_S = 5.0
#: Steps the synchronization window gave up waiting for are warned about at once, then at
#: most this often (s of sim time), with their count.
SYNC_WARN_PERIOD_S = 5.0
#: While paused, the loop looks for commands and shutdown this often (s, wall).
PAUSED_POLL_S = 0.01
#: The per-step messages: topic, key of its rate in `rates_hz`, name in
#: SimMessages.step_wires.
STEP_MESSAGES = (
    (topics.JOINT_STATES, 'joint_states', 'joint_state'),
    (topics.IMU, 'imu', 'imu'),
    (topics.L_FOOT_CONTACT, 'contact', 'l'),
    (topics.R_FOOT_CONTACT, 'contact', 'r'))
#: DRCSim's messages filled only when due and someone listens (an unheard one costs a
#: test per step): topic, key of its rate in `rates_hz`, name in SimMessages.on_demand.
ON_DEMAND_MESSAGES = (
    (topics.ATLAS_STATE, 'atlas_state', 'atlas_state'),
    (topics.FORCE_TORQUE_SENSORS, 'force_torque_sensors', 'force_torque_sensors'),
    (topics.DEBUG_L_FOOT_CONTACT, 'debug_contact', 'debug_l'),
    (topics.DEBUG_R_FOOT_CONTACT, 'debug_contact', 'debug_r'))
#: Their rate (Hz of sim time) when `rates_hz` does not name it: DRCSim's 1 kHz.
ON_DEMAND_RATE_HZ = 1000.0
#: The links' /tf rate (Hz of sim time): robot_state_publisher's publish_frequency in
#: DRCSim's launch.
LINKS_TF_RATE_HZ = 50.0
#: Rows (arrays.LAW_FIELDS indices) each command topic can set; DAMPING_ROW stands for
#: /atlas/debug/test's damping. An older message whose rows a newer one set for every
#: joint is dropped undecoded (apply_pending_commands).
DAMPING_ROW = len(LAW_FIELDS)
CAN_SET: dict[str, frozenset[int]] = {
    topics.JOINT_COMMANDS: frozenset(range(len(FIELD_NAMES))),
    topics.ATLAS_COMMAND: frozenset(range(len(LAW_FIELDS))),
    topics.ATLAS_TEST: frozenset({DAMPING_ROW, *(LAW_FIELDS.index(name) for name in (
        'kp_position', 'ki_position', 'kd_position', 'kp_velocity', 'i_effort_min',
        'i_effort_max', 'k_effort'))}),
}
#: Where DRCSim takes the command's header stamp for /atlas/controller_statistics.
STAMPED_COMMANDS = (topics.JOINT_COMMANDS, topics.ATLAS_COMMAND)


class Outbox(Protocol):
    """Where serialized messages go, by outlet (the node: its publishers, in a WireBatch)."""

    def wanted(self, outlet: Hashable) -> bool:
        """Anyone listening? The loop serializes nothing for an outlet without listeners."""

    def add(self, outlet: Hashable, data: bytes | bytearray) -> None:
        """Queue a copy of `data` (TCPROS-framed messages) after what is queued."""

    def replace(self, outlet: Hashable, data: bytes | bytearray) -> None:
        """Queue `data` instead of anything still queued for `outlet`."""

    def flush(self) -> None:
        """Send everything queued."""


class LoopLog(Protocol):
    """The loop's log lines (the node: rospy's log, which throttles refused commands)."""

    def info(self, text: str) -> None: ...

    def refused_command(self, text: str, topic: str = topics.JOINT_COMMANDS) -> None:
        """Throttled per topic: a command message was refused."""

    def kept_fields(self, text: str, topic: str) -> None:
        """Throttled per topic: an AtlasCommand/Test array of the wrong length was left out."""

    def warn(self, text: str) -> None: ...

    def error(self, text: str) -> None: ...

    def fatal(self, text: str) -> None: ...


class DivergenceGuard:
    """Retry after a divergence (reset the robot), unless the model keeps diverging.

    A divergence within DIVERGENCE_REPEAT_S of sim time after the previous one is "in a
    row"; the MAX_DIVERGENCES_IN_A_ROW-th in a row stops the loop.
    """

    def __init__(self) -> None:
        self.in_a_row = 0
        self.last_ns: int | None = None

    def retry(self, now_ns: int) -> bool:
        """A divergence at sim time `now_ns`: True to reset and go on, False to stop."""
        last_ns = self.last_ns
        if last_ns is not None and 0 <= now_ns - last_ns <= DIVERGENCE_REPEAT_S * NS_PER_S:
            self.in_a_row += 1
        else:
            self.in_a_row = 1
        self.last_ns = now_ns
        return self.in_a_row < MAX_DIVERGENCES_IN_A_ROW


@dataclass(frozen=True)
class ResetControlsRequest:
    """atlas_msgs/ResetControls' request, with what the node read for it.

    Attributes:
        atlas_command: the request's AtlasCommand, serialized.
        gains: with reload_pid_from_ros, the gains on the parameter server, or the
            reason they could not be read (GainsError's text).
    """

    reset_bdi_controller: bool
    reset_pid_controller: bool
    reload_pid_from_ros: bool
    atlas_command: bytes
    gains: Gains | str | None = None


class SteppingLoop:
    """Owns the simulator's lock, its pending commands and the stepping loop.

    Args:
        sim: the simulator.
        outbox: where messages go.
        outlets: topic -> outlet (key in the outbox) of each published topic; without
            topics.TF, no /tf.
        rates_hz: rate (Hz of sim time; 0 = every step) of 'joint_states', 'imu',
            'contact' (both feet), 'odom' and, with a /tf outlet, 'tf'; optionally of
            'atlas_state', 'force_torque_sensors', 'debug_contact' (else
            ON_DEMAND_RATE_HZ). An ON_DEMAND_MESSAGES topic without an outlet is not sent.
        statistics: the command age statistics of /atlas/controller_statistics.
        log: where log lines go.
        publish_config: sends /atlas/sim_config's JSON (latched: not through the outbox).
        real_time_factor: sim time per wall time; 0 = as fast as possible.
        paused: start with physics paused.
        pacer: the wall-time decisions (default: a Pacer at real_time_factor; tests give
            one with a fake clock).
        publish_input: sends /atlas/sim_inputs' JSON of each applied cheat (None: nowhere).
        synchronization: DRCSim 2.6's synchronization window (default: DRCSim's budgets);
            its statistics go to the topics.SYNCHRONIZATION_STATISTICS outlet, if any.
        latch_synchronization: keeps the latest statistics message (serialized, without
            its length prefix) for later subscribers (None: not kept).
        links: with a /tf outlet, the links' transforms published in robot_state_publisher's
            stead (link_transforms.py), at rates_hz['links_tf'] (default
            LINKS_TF_RATE_HZ, as robot_state_publisher's publish_frequency); None: not.
    """

    def __init__(self, sim: AtlasSimulator, outbox: Outbox, outlets: Mapping[str, Hashable],
                 rates_hz: Mapping[str, float], statistics: CommandAgeStatistics,
                 log: LoopLog, publish_config: Callable[[str], None],
                 real_time_factor: float = 0.0, paused: bool = False,
                 pacer: Pacer | None = None,
                 publish_input: Callable[[str], None] | None = None,
                 synchronization: SynchronizationWindow | None = None,
                 latch_synchronization: Callable[[bytes], None] | None = None,
                 links: LinkTransforms | None = None) -> None:
        self.sim = sim
        self._send_input = publish_input
        self._input_logged_ns: dict[str, int] = {}  # kind -> sim time it was last logged
        self.lock = threading.Lock()
        self.outbox = outbox
        self.log = log
        self._send_config = publish_config
        self.paused = paused
        self.pacer = pacer if pacer is not None else Pacer(real_time_factor)
        self.step_count = 0
        self.exit_status = 0
        self.divergences = DivergenceGuard()
        rates_hz = {**{key: ON_DEMAND_RATE_HZ for _, key, _ in ON_DEMAND_MESSAGES}, **rates_hz}
        self.every = {key: steps_between(rate, sim.dt_s) for key, rate in rates_hz.items()}

        # What each message holds is sim_messages' (shared with offline runs).
        self.messages = messages = SimMessages(sim)
        # Those due at the same steps are filled by one plan (at the launch's rates, all).
        due_together: dict[int, list[str]] = {}
        for _, rate_key, name in STEP_MESSAGES:
            due_together.setdefault(self.every[rate_key], []).append(name)
        self.fill_plans = tuple((every, messages.fill_plan(names))
                                for every, names in due_together.items())
        # (every how many steps, wire message, outlet, stamped at the step's end).
        self.step_wires = tuple(
            (self.every[rate_key], messages.step_wires[name], outlets[topic],
             topic in STAMPED_AT_STEP_END)
            for topic, rate_key, name in STEP_MESSAGES)
        # (every how many steps, fill (True: send), wire message, outlet, stamped at end).
        self.demand_wires = tuple(
            (self.every[rate_key], messages.on_demand[name][1], messages.on_demand[name][0],
             outlets[topic], topic in STAMPED_AT_STEP_END)
            for topic, rate_key, name in ON_DEMAND_MESSAGES if topic in outlets)
        self.clock_outlet = outlets[topics.CLOCK]
        self.odom_outlet = outlets[topics.GROUND_TRUTH_ODOM]
        self.tf_outlet = outlets.get(topics.TF)
        # The links' /tf, decided as robot_state_publisher decides on each joint_states.
        self.links_schedule: RspSchedule | None = None
        if links is not None and self.tf_outlet is not None:
            messages.use_link_transforms(links)
            self.links_schedule = RspSchedule(rates_hz.get('links_tf', LINKS_TF_RATE_HZ))

        # /atlas/controller_statistics, fed and published only while someone listens.
        self.statistics = statistics
        self.statistics_msg = ControllerStatisticsWire()
        self.statistics_outlet = outlets[topics.CONTROLLER_STATISTICS]

        # Commands wait here, undecoded, for the loop (see receive_command). Bounded, so
        # that a stalled loop cannot make it grow without limit; emptied every step.
        self.decoder = CommandDecoder()
        self.pending_commands: collections.deque[tuple[str, bytes]] = collections.deque(
            maxlen=MAX_PENDING_COMMANDS)
        # DRCSim 2.6's synchronization window (synchronization.py): on while the latest
        # AtlasCommand's desired_controller_period_ms is non-zero. A command wakes the wait.
        self.desired_controller_period_ms = 0
        self.command_stamp_ns = 0  # header.stamp of the newest applied command, as sent
        self.synchronization = (synchronization if synchronization is not None
                                else SynchronizationWindow(DelayBudgets()))
        self.sync_outlet = outlets.get(topics.SYNCHRONIZATION_STATISTICS)
        self._latch_sync = latch_synchronization
        self._command_arrived = threading.Event()
        #: Blocks up to the given seconds (wall) for a command; True when woken (tests
        #: replace it to drive the window with a fake clock).
        self.wait_for_command: Callable[[float], bool] = self._command_arrived.wait
        self._sync_warned_ns: int | None = None
        self._sync_gave_up = 0
        self._stopping = False  # shutting down: no more waits

        # Headless feedback (a log line per fall, per reset, and for ignored commands).
        self.pelvis_z_index = sim.atlas.free_qpos_adr + 2  # the pelvis height in qpos
        self.fall_armed = True  # one line per fall: disarmed by it, re-armed by a reset
        self.first_command_ns: int | None = None  # since the start or last reset
        self.not_user_warned_ns: int | None = None

    @property
    def real_time_factor(self) -> float:
        """Sim time per wall time (the pacer's); 0 = as fast as possible."""
        return self.pacer.real_time_factor

    # -- inputs, from other threads ------------------------------------------------------
    def receive_command(self, raw: bytes, topic: str = topics.JOINT_COMMANDS) -> None:
        """Queue a serialized osrf_msgs/JointCommands (or, by `topic`, an
        atlas_msgs/AtlasCommand or Test) for the next step, undecoded.

        Nothing else happens in the receiving thread: decoding there would make several
        fast publishers' threads and the loop fight over the GIL. One queue keeps the
        topics' messages in the order they came: the newest sets the fields it carries.
        """
        self.pending_commands.append((topic, raw))
        if self.desired_controller_period_ms:
            self._command_arrived.set()  # the window may be waiting for it

    def wake(self) -> None:
        """End the synchronization window's current wait early (DRCSim's
        /atlas/debug/sync_delay): it checks the commands again."""
        self._command_arrived.set()

    def stop_waiting(self) -> None:
        """At shutdown: end the current wait and wait no more (a step's budget may be
        long, and the controller gone)."""
        self._stopping = True
        self._command_arrived.set()

    def _decode(self, topic: str, raw: bytes) -> CommandUpdate | AtlasUpdate:
        if topic == topics.JOINT_COMMANDS:
            return self.decoder.decode(raw)
        if topic == topics.ATLAS_COMMAND:
            return decode_atlas_command(raw)
        return decode_test(raw)

    def apply_pending_commands(self) -> None:
        """Decode, check and merge the commands received since the last step, in order.

        Newest first: a message that sets some fields for every joint hides those fields
        of all that came before it, so an older message with nothing else to set is
        dropped undecoded (DRCSim, too, applied only the latest command at each step).
        Controllers send such complete commands, so a flood costs one decode per step,
        not one per message.
        """
        pending = self.pending_commands
        received = []
        while pending:
            received.append(pending.popleft())
        hidden: set[int] = set()
        decoded: list[tuple[str, CommandUpdate | AtlasUpdate]] = []
        stamped = False
        for topic, raw in reversed(received):
            if CAN_SET[topic] <= hidden:
                continue
            try:
                result = self._decode(topic, raw)
            except CommandError as err:
                self.log.refused_command(f'refused {topic}: {err}; previous command kept', topic)
                continue
            if not stamped and topic in STAMPED_COMMANDS:
                self._note_command_stamp(raw)  # the newest applied command
                stamped = True
            decoded.append((topic, result))
            update = result if isinstance(result, CommandUpdate) else result.update
            if update.all_joints:
                hidden.update(update.rows)
            if isinstance(result, AtlasUpdate) and result.damping is not None:
                hidden.add(DAMPING_ROW)
        if decoded:
            self._apply(decoded[::-1])

    def _apply(self, decoded: list[tuple[str, CommandUpdate | AtlasUpdate]]) -> None:
        """Apply decoded messages, oldest first."""
        updates = []
        for topic, result in decoded:
            if isinstance(result, CommandUpdate):
                updates.append(result)
                continue
            if result.ignored:
                self.log.kept_fields(f'{topic}: {result.ignored_text()}', topic)
            if result.damping is not None:
                self.sim.set_joint_damping(result.damping)
            if result.desired_controller_period_ms is not None:
                self._store_period(result.desired_controller_period_ms)
            updates.append(result.update)
        first = self.sim.user_command is None
        self.sim.receive_updates(updates)
        if (self.sim.mode is not ControlMode.USER
                and any(topic == topics.JOINT_COMMANDS for topic, _ in decoded)):
            self._warn_not_user()  # AtlasCommands with k_effort act in any mode
        if first:
            self.first_command_ns = self.sim.sim_time_ns
            # Which command a trajectory started from: a late one makes the robot jump.
            self.log.info(f'first {decoded[0][0]} since the start or last reset, at '
                          f't={self.sim.sim_time_ns / NS_PER_S:.3f} s '
                          f'({self.sim.mode.value} mode)')

    def _warn_not_user(self) -> None:
        """Commands arrived in a mode that does not apply them: say how to switch (the
        tutorial's step most often forgotten), at once, then every NOT_USER_WARN_PERIOD_S."""
        now_ns = self.sim.sim_time_ns
        last_ns = self.not_user_warned_ns
        if last_ns is not None and 0 <= now_ns - last_ns < NOT_USER_WARN_PERIOD_S * NS_PER_S:
            return  # (a rewind, reset_simulation, warns again)
        self.not_user_warned_ns = now_ns
        self.log.warn(f'{topics.JOINT_COMMANDS} arrive in {self.sim.mode.value} mode, which does '
                      f'not apply them; switch to User mode: {topics.SWITCH_TO_USER}')

    def _store_period(self, period_ms: int) -> None:
        """An AtlasCommand's desired_controller_period_ms; a line when the window turns
        on or off."""
        previous = self.desired_controller_period_ms
        self.desired_controller_period_ms = period_ms
        if bool(previous) == bool(period_ms):
            return
        if period_ms:
            budgets = self.synchronization.budgets
            self.log.info(f'synchronization window on ({topics.ATLAS_COMMAND} '
                          f'desired_controller_period_ms = {period_ms}): each step waits for '
                          f'a command stamped no more than {period_ms} ms before its end, at '
                          f'most {budgets.max_per_step_s:g} s per step and '
                          f'{budgets.max_per_window_s:g} s per {budgets.window_size_s:g} s')
        else:
            self.log.info('synchronization window off (desired_controller_period_ms = 0)')

    def reset_controls(self, request: ResetControlsRequest) -> tuple[bool, str]:
        """atlas_msgs/ResetControls, as AtlasPlugin::ResetControls: (success, status).

        Commands received before the request are applied first. Everything is checked
        before anything is done: a refused request changes nothing.
        """
        with self.lock:
            self.apply_pending_commands()
            atlas: AtlasUpdate | None = None
            if request.reload_pid_from_ros:
                if not isinstance(request.gains, Gains):
                    return False, (f'reload_pid_from_ros: {request.gains}; nothing was done')
            else:
                try:
                    atlas = decode_atlas_command(request.atlas_command)
                except CommandError as err:
                    return False, f'atlas_command refused: {err}; nothing was done'
            done = []
            if request.reset_bdi_controller:
                done.append('reset_bdi_controller: there is no BDI controller in this '
                            'simulator, nothing to reset')
            if request.reset_pid_controller:
                self.sim.reset_pid()
                done.append('PID state reset (integral terms and previous errors)')
            if atlas is None:
                assert isinstance(request.gains, Gains)
                self.sim.load_gains(request.gains)
                done.append(f'gains reloaded from {topics.GAINS_PARAM}, k_effort 255 on every '
                            'joint (atlas_command ignored)')
            else:
                done.extend(self._load_atlas_command(atlas))
        return True, '; '.join(done)

    def _load_atlas_command(self, atlas: AtlasUpdate) -> list[str]:
        """ResetControls' atlas_command applied as an AtlasCommand; what was done."""
        done = []
        if atlas.update.rows:
            self.sim.receive_updates([atlas.update])
            done.append('atlas_command loaded: ' + ', '.join(atlas.fields_set()))
        else:
            done.append(f'atlas_command has no array of {NUM_JOINTS}: no field loaded')
        if atlas.ignored:
            done.append(atlas.ignored_text())
        assert atlas.desired_controller_period_ms is not None
        self._store_period(atlas.desired_controller_period_ms)
        return done

    def set_mode(self, mode: ControlMode) -> ControlMode:
        """Switch the control mode; returns the previous one.

        Commands received before the switch are applied first, as DRCSim's single callback
        queue did: the switch then sets their k_effort (AtlasPlugin::OnRobotMode).
        """
        with self.lock:
            self.apply_pending_commands()
            previous = self.sim.mode
            self.sim.set_mode(mode)
            self.not_user_warned_ns = None  # a new mode: warn again at once
        return previous

    def apply_input(self, item: SimInput) -> None:
        """Apply one checked VRCPlugin input between two steps, then log and publish it (the
        replay re-applies it before the same step)."""
        with self.lock:
            self.sim.apply_input(item)
            event = self.sim.last_input_event()
        if self._send_input is not None:
            self._send_input(event.to_json())
        last_ns = self._input_logged_ns.get(item.kind)
        if last_ns is None or not 0 <= event.time_ns - last_ns < INPUT_LOG_PERIOD_S * NS_PER_S:
            self._input_logged_ns[item.kind] = event.time_ns
            self.log.info(f'applied at t={event.time_ns / NS_PER_S:.3f} s: '
                          f'{describe_input(item)}')

    def publish_config(self) -> None:
        """(Re-)publish /atlas/sim_config: at start and after every reset."""
        self._send_config(self.sim.config().to_json())

    def reset_world(self, by: str = '') -> None:
        """/gazebo/reset_world, or the viewer's Reset (`by`: ' (viewer)', said in the line)."""
        with self.lock:
            self.sim.reset_world()
            self._rearm()
        self.publish_config()
        self.log.info(f'reset_world{by}: robot back to its initial pose at '
                      f't={self.sim.sim_time_ns / NS_PER_S:.3f} s (torso pinned '
                      f'for {self.sim.time_to_unpin_s} s)')

    def reset_simulation(self) -> None:
        with self.lock:
            self.sim.reset_simulation()
            self.statistics.forget_command()  # its stamp lies in the rewound future
            self.command_stamp_ns = 0
            self._rearm()
        self.publish_config()
        self.log.info('reset_simulation: robot reset and sim time back to 0')

    def pause(self) -> None:
        self.paused = True
        self.log.info('physics paused')

    def unpause(self) -> None:
        self.paused = False
        self.log.info('physics unpaused')

    def _rearm(self) -> None:
        """After a reset: the next fall and the next first command are new."""
        self.fall_armed = True
        self.first_command_ns = None
        self.not_user_warned_ns = None

    def watch_fall(self) -> None:
        """After a step: one line when the pelvis drops below FALL_HEIGHT_M (headless, the
        only sign of a fall), then nothing until a reset."""
        if self.fall_armed and self.sim.data.qpos[self.pelvis_z_index] < FALL_HEIGHT_M:
            self.fall_armed = False
            sim = self.sim
            after_s = (None if self.first_command_ns is None else
                       (sim.sim_time_ns - self.first_command_ns) / NS_PER_S)
            self.log.info(fall_line(FALL_HEIGHT_M, sim.sim_time_ns / NS_PER_S, after_s))

    # -- publishing ----------------------------------------------------------------------
    def publish(self) -> None:
        """Serialize what is due this step into the outbox (called under the lock)."""
        sim = self.sim
        now_ns = sim.sim_time_ns
        outbox = self.outbox
        wanted = outbox.wanted
        if wanted(self.clock_outlet):
            # Only the latest time goes out per flush: every step when paced, about one
            # per FLUSH_PERIOD_S of wall time at real_time_factor 0 (what a sim-time timer
            # sees at real time); spares the recorder one message in five.
            outbox.replace(self.clock_outlet, clock_bytes(now_ns))
        count = self.step_count
        for every, plan in self.fill_plans:
            if count % every == 0:
                plan()
        # Poses and sensors describe the state at the start of the last step (schedule.py).
        sensed_ns = sim.state_time_ns
        for every, message, outlet, at_end in self.step_wires:
            if count % every == 0 and wanted(outlet):
                outbox.add(outlet, message.stamped(now_ns if at_end else sensed_ns))
        for every, fill, message, outlet, at_end in self.demand_wires:
            if count % every == 0 and wanted(outlet) and fill():
                outbox.add(outlet, message.stamped(now_ns if at_end else sensed_ns))
        messages = self.messages
        if count % self.every['odom'] == 0 and wanted(self.odom_outlet):
            outbox.add(self.odom_outlet, messages.odometry(sensed_ns))
        tf_outlet = self.tf_outlet
        if tf_outlet is not None and count % self.every['tf'] == 0 and wanted(tf_outlet):
            outbox.add(tf_outlet, messages.pelvis_tf(sensed_ns))
        links = self.links_schedule  # stamped as the joint_states published with them
        if (links is not None and count % self.every['joint_states'] == 0
                and links.due(now_ns) and wanted(tf_outlet)):
            outbox.add(tf_outlet, messages.links_tf(now_ns))

    def _note_command_stamp(self, raw: bytes) -> None:
        """The command in `raw` is applied from the coming step on: remember its stamp."""
        stamp_ns = FieldCursor(raw).header_stamp_ns()
        self.command_stamp_ns = stamp_ns
        self.statistics.command_applied(stamp_ns, self.sim.sim_time_ns + self.sim.step_ns)

    def _publish_controller_statistics(self, now_ns: int) -> None:
        """After each step: the command age at `now_ns`, into the window and, when due, out."""
        if not self.outbox.wanted(self.statistics_outlet):
            return
        stats = self.statistics
        stats.update(now_ns)
        if stats.publication_due(now_ns):
            self.statistics_msg.set_values(stats.age_s, stats.mean_s, stats.variance_s2,
                                           stats.window_s)
            self.outbox.add(self.statistics_outlet, self.statistics_msg.stamped(now_ns))

    # -- the loop ------------------------------------------------------------------------
    def run(self, is_shutdown: Callable[[], bool]) -> int:
        """Step, publish and pace against wall time until `is_shutdown()`; the exit status
        (1: stopped because the physics kept diverging)."""
        sim, lock, outbox, pacer = self.sim, self.lock, self.outbox, self.pacer
        paced = pacer.real_time_factor > 0.0  # else there is nothing to wait for
        pacer.restart(sim.sim_time_ns)
        with lock:
            self.publish()  # /clock and the initial state before the first step
        outbox.flush()
        pacer.flushed()
        while not is_shutdown():
            if self.paused:
                with lock:
                    self.apply_pending_commands()
                outbox.flush()
                pacer.sleep(PAUSED_POLL_S)
                pacer.restart(sim.sim_time_ns)
                continue
            if self.desired_controller_period_ms:
                self._synchronize()
            with lock:
                self.apply_pending_commands()
                try:
                    sim.step()
                except PhysicsDivergenceError as err:
                    if not self._recover(err):
                        break
                self.step_count += 1
                if self.fall_armed:
                    self.watch_fall()
                self.publish()
                self._publish_controller_statistics(sim.sim_time_ns)
                sim_ns = sim.sim_time_ns
            # Send outside the lock, in batches when allowed (pacing.py): TCPROS is a byte
            # stream, one sendall carries many messages.
            if pacer.flush_due(sim_ns):
                outbox.flush()
            if paced:
                pacer.wait(sim_ns)
        return self.exit_status

    # -- the synchronization window -----------------------------------------------------
    def _synchronize(self) -> None:
        """Before a step: wait, within the budgets, for a command fresh enough
        (synchronization.py); queue /atlas/synchronization_statistics.

        The wait replaces none of the pacing: at real_time_factor > 0 the time waited is
        part of the step's wall time, and the pacer (pacing.py) sleeps only what is left
        of the step's share, or catches up when the wait made the loop late.
        """
        report = self.synchronization.enforce(self._command_fresh, self._wait_sent)
        if report.outcome is not SyncOutcome.FRESH:
            self._warn_gave_up(report)
        outlet = self.sync_outlet
        if outlet is None:
            return
        data = statistics_bytes(report)
        if self.outbox.wanted(outlet):
            self.outbox.add(outlet, data)
        if self._latch_sync is not None:
            self._latch_sync(data[4:])

    def _command_fresh(self) -> bool:
        """Apply what arrived; True when the newest command is fresh enough for the coming
        step, or no longer asks for the window; True at shutdown (wake() ends the wait)."""
        self._command_arrived.clear()  # before looking: a later arrival wakes the wait
        if self._stopping:
            return True
        with self.lock:
            self.apply_pending_commands()
            period_ms = self.desired_controller_period_ms
            return period_ms == 0 or is_fresh(self.sim.sim_time_ns + self.sim.step_ns,
                                              self.command_stamp_ns, period_ms)

    def _wait_sent(self, timeout_s: float) -> bool:
        """Send what is queued (the state the controller must answer), then wait."""
        self.outbox.flush()
        self.pacer.flushed()
        return self.wait_for_command(timeout_s)

    def _warn_gave_up(self, report: DelayReport) -> None:
        """A step went on without a fresh command: a line at once, then one per
        SYNC_WARN_PERIOD_S of sim time with the count (DRCSim warned at every one)."""
        self._sync_gave_up += 1
        now_ns = self.sim.sim_time_ns
        last_ns = self._sync_warned_ns
        if last_ns is not None and 0 <= now_ns - last_ns < SYNC_WARN_PERIOD_S * NS_PER_S:
            return
        self._sync_warned_ns = now_ns
        count, self._sync_gave_up = self._sync_gave_up, 0
        self.log.warn(f'synchronization window: no command stamped within '
                      f'{self.desired_controller_period_ms} ms of t='
                      f'{(now_ns + self.sim.step_ns) / NS_PER_S:.3f} s ({report.outcome.value}, '
                      f'{report.delay_in_window_s:.3f} s waited in this window); stepping on '
                      f'with the latest command ({count} step(s) so since the last such line; '
                      'controller stopped or messages lost?)')

    def _recover(self, err: PhysicsDivergenceError) -> bool:
        """Log a divergence and reset the robot; False (stop) when the model keeps diverging."""
        if not self.divergences.retry(self.sim.sim_time_ns):
            self.log.fatal(f'{err}: {MAX_DIVERGENCES_IN_A_ROW} times in a row, each within '
                           f'{DIVERGENCE_REPEAT_S} s of the reset; the model '
                           f'{self.sim.atlas_path} is unstable; stopping the simulator')
            self.exit_status = 1
            return False
        self.log.error(f'{err}; resetting the robot to its initial state')
        self.sim.reset_world()
        self._rearm()
        self.publish_config()
        return True
