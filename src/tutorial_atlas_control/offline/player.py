"""Offline runs: play a trajectory into the simulator without ROS, deterministically, to a bag.

`run_offline.py YAML_FILE NAME` does what `make demo` does (spawn, wait past the torso
pin, switch to User, play the trajectory with traj_yaml's schedule, settle) but in one
process, on the simulator's own clock, as fast as the machine steps it: no master, no
transport, no scheduling jitter, so two runs of the same inputs are identical.

Each piece is the live one: trajectory loading and validation (trajectory.py), the
schedule (schedule.run_trajectory), the commands traj_yaml sends (every field as
traj_yaml_node.build_command sets it), the simulator decoding them (joint_commands.CommandDecoder)
and stepping (AtlasSimulator), its messages (sim_messages.SimMessages). The bag has the
topics, types, MD5 sums and header stamps of a recorded live run (/clock thinned to
CLOCK_PERIOD_NS), so every bag tool reads it as one.
"""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

# numpy (2.x) imports numpy.random at its first use; imported here with the module, before
# the run begins: a Ctrl-C landing in that import's compiled part was lost, and the run went
# on simulating.
from numpy.random import default_rng

from tutorial_atlas_control import topics
from tutorial_atlas_control.asi import AtlasSimInterface
from tutorial_atlas_control.bags import (
    JOINT_COMMANDS_TYPE,
    BlockBagWriter,
    RecordBlock,
    TopicConnection,
    load_typestore,
    rosbags_msgtype,
)
from tutorial_atlas_control.command import CommandError, CommandUpdate
from tutorial_atlas_control.course import ScoreRow, check_mud_damping
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import ATLAS_PREFIX, JOINT_NAMES
from tutorial_atlas_control.msgs import CommandDecoder, JointCommandsWire, StampedWire, clock_bytes
from tutorial_atlas_control.offline.world import OfflineWorld
from tutorial_atlas_control.sensors import HeadSensors
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    TCPROS_PREFIX_BYTES,
    AtlasSimulator,
    ControlMode,
    Gains,
    PhysicsDivergenceError,
    SimInput,
    SimMessages,
    load_gains_yaml,
    load_model,
)
from tutorial_atlas_control.stepping import (
    CourseScoring,
    StepController,
    Tick,
    step_stamp,
    steps_between,
)
from tutorial_atlas_control.trajectories import (
    Waypoint,
    done_line,
    load_trajectory,
    locate_trajectory_file,
    playing_line,
    run_trajectory,
    trajectory_log_line,
)
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['CommandLatency', 'OfflinePlayer', 'OfflineRunError', 'OfflineRun', 'open_offline_bag',
           'run_offline', 'write_offline_bag', 'write_whole']

#: Sim time (s) before the switch to User, as `make demo`: past the 1 s torso pin.
DEFAULT_START_AFTER_S = 1.5
#: Sim time (s) the robot is left alone after the last command, as `make demo`.
DEFAULT_SETTLE_S = 3.0
#: /clock is written every this many ns of sim time (the live simulator sends it every
#: step; nothing reads a bag's /clock at that rate, and it is a fifth of the records).
CLOCK_PERIOD_NS = 10_000_000
#: /ground_truth_odom's rate (Hz), the simulator's default (~odom_rate).
ODOM_RATE_HZ = topics.BY_NAME[topics.GROUND_TRUTH_ODOM].rate.default_hz
#: /multisense_sl/laser/scan's rate (Hz), the simulator's default (~laser_rate).
LASER_RATE_HZ = topics.BY_NAME[topics.LASER_SCAN].rate.default_hz
#: Who published what in a live run: the bag's connections name them as callers.
SIMULATOR_NODE = '/atlas_sim'
PLAYER_NODE = '/tutorial_atlas_control'
#: rosgraph_msgs/Log's INFO level.
LOG_INFO = 2
#: Called after each step with the simulator (write_offline_bag's `on_step`).
StepHook = Callable[[AtlasSimulator], None]
#: Bag chunk size (bytes): rosbag record's default.
CHUNK_BYTES = 768 * 1024
#: Chunk compression, a live run's default (atlas.launch's compression:=lz4): an 8.5 s
#: step_and_fall run takes 8.8 MB instead of 16.3 MB, in no measurably longer time.
CHUNK_COMPRESSION = 'lz4'

#: Topic -> its bag connection: type, publishing node (the simulator for what it
#: publishes, the player for the rest), latched; topics.INTERFACE's offline rows, in its
#: order (the bag's connections' ids).
TOPIC_TYPES: dict[str, TopicConnection] = {
    topic.name: TopicConnection(
        rosbags_msgtype(topic.msg_type),
        SIMULATOR_NODE if topic.direction is topics.Direction.PUBLISHED else PLAYER_NODE,
        topic.delivery.latched)
    for topic in topics.INTERFACE if topic.delivery.offline}
#: The head laser's connection, in a bag asked to hold its scans (open_offline_bag).
LASER_CONNECTION = {topics.LASER_SCAN: TopicConnection(
    rosbags_msgtype(topics.MSG_TYPES[topics.LASER_SCAN]), SIMULATOR_NODE, False)}


@dataclass(frozen=True)
class CommandLatency:
    """Live delivery, modelled: each command takes effect a whole number of steps later,
    drawn uniformly from [min_steps, max_steps] by a generator seeded with `seed`.

    Live, traj_yaml wakes on the /clock after a send is due and the node applies the command
    at its next step (1-3 steps at real time, more on a busy machine); offline every command
    takes effect at once. Commands keep their order, as over one TCP connection.
    """

    min_steps: int
    max_steps: int
    seed: int = 0

    def __post_init__(self) -> None:
        if not 0 <= self.min_steps <= self.max_steps:
            raise ValueError(f'latency {self.min_steps}..{self.max_steps} steps is not a range')


class OfflineRunError(AtlasControlError):
    """An offline run cannot start or finish; nothing was written."""


@dataclass(frozen=True)
class OfflineRun:
    """What an offline run did: its bag, commands sent, sim time covered and wall time taken."""

    bag: Path
    commands: int
    sim_time_s: float
    steps: int
    wall_s: float

    @property
    def real_time_factor(self) -> float:
        return self.sim_time_s / self.wall_s if self.wall_s > 0 else float('inf')


#: Steps whose 1 kHz messages are buffered, then stamped and written to the bag in one go.
BLOCK_STEPS = 500


def open_offline_bag(path: Path, scans: bool = False) -> BlockBagWriter:
    """A new bag at `path` with a live run's connections (TOPIC_TYPES); with `scans`, the
    head laser's too, which the player then writes (a fifth of an offline run's time: 13.9
    instead of 17.2 times real time, load 3.3)."""
    typestore = load_typestore()
    if JOINT_COMMANDS_TYPE not in typestore.fielddefs:
        raise OfflineRunError('cannot find osrf_msgs/JointCommands.msg (msg/osrf_msgs in '
                              'the package): the commands could not be written')
    connections = {**TOPIC_TYPES, **(LASER_CONNECTION if scans else {})}
    return BlockBagWriter(path, typestore, connections, CHUNK_BYTES, CHUNK_COMPRESSION)


def _serialized(message: StampedWire) -> np.ndarray:
    """A live uint8 view of `message`'s ROS 1 serialization (without the TCPROS prefix)."""
    return np.frombuffer(message.buf, dtype=np.uint8)[TCPROS_PREFIX_BYTES:]


class _StepRows:
    """What the simulator node publishes after each step, kept as rows of numbers (qpos,
    qvel, torque, sensordata, stamps); every BLOCK_STEPS steps they become messages, all
    at once (write_steps): the joint states, and the table's sensor messages through
    SimMessages.sensor_selection. In a bag opened with the laser's connection
    (open_offline_bag's `scans`), the head's laser scans are written as they are cast.
    """

    def __init__(self, sim: AtlasSimulator, sink: BlockBagWriter) -> None:
        self.sim = sim
        self.sink = sink
        #: The head's laser and spindle (stepped by the player with each step).
        self.head = HeadSensors(sim.model, sim.data, sim.dt_s, sim.sensor_seed)
        self.laser_every = (steps_between(LASER_RATE_HZ, sim.dt_s)
                            if topics.LASER_SCAN in sink.msgtypes else 0)
        self.messages = messages = SimMessages(sim)
        self.joint_states = self._block(topics.JOINT_STATES, messages.joint_state_wire)
        self.odometry = self._block(topics.GROUND_TRUTH_ODOM, messages.odometry_wire)
        selections = {topic.name: messages.sensor_selection(topic.delivery.message)
                      for topic in topics.INTERFACE if topic.delivery.offline
                      and topic.delivery.message in SimMessages.SENSOR_MESSAGES}
        self.sensor_blocks = {topic: (self._block(topic, selection.wire), selection)
                              for topic, selection in selections.items()}
        wire = messages.joint_state_wire
        self.joint_views = [self.joint_states.float_view(_offset_in(wire, view), len(view))
                            for view in (wire.position, wire.velocity, wire.effort)]
        data = sim.data
        self.qpos = np.empty((BLOCK_STEPS, len(data.qpos)))
        self.qvel = np.empty((BLOCK_STEPS, len(data.qvel)))
        self.torque = np.empty((BLOCK_STEPS, len(sim.torque_nm)))
        self.sensordata = np.empty((BLOCK_STEPS, len(data.sensordata)))
        self.now_ns = np.empty(BLOCK_STEPS, dtype=np.int64)
        self.sensed_ns = np.empty(BLOCK_STEPS, dtype=np.int64)
        self.count = 0
        self.odom_every = steps_between(ODOM_RATE_HZ, sim.dt_s)
        self.next_clock_ns = 0

    def _block(self, topic: str, message: StampedWire) -> RecordBlock:
        """Rows for BLOCK_STEPS records of `topic`, laid out like `message`."""
        return self.sink.record_block(topic, _serialized(message), BLOCK_STEPS)

    def publish(self, steps: int) -> None:
        """Keep what the simulator node sends after step `steps`, recorded at the time it
        sends it."""
        sim = self.sim
        data = sim.data
        now_ns = sim.sim_time_ns
        if now_ns >= self.next_clock_ns:
            self.sink.write(topics.CLOCK, now_ns, clock_bytes(now_ns)[TCPROS_PREFIX_BYTES:])
            self.next_clock_ns = now_ns + CLOCK_PERIOD_NS
        k = self.count
        self.now_ns[k] = now_ns
        self.sensed_ns[k] = sim.state_time_ns  # poses and sensors: the step's start
        self.qpos[k] = data.qpos
        self.qvel[k] = data.qvel
        self.torque[k] = sim.torque_nm
        self.sensordata[k] = data.sensordata
        if steps % self.odom_every == 0:
            self.messages.fill_odometry()
            self.odometry.add(now_ns, sim.state_time_ns)
            self.sink.write(topics.TF, now_ns,
                            self.messages.pelvis_tf(sim.state_time_ns)[TCPROS_PREFIX_BYTES:])
        if self.laser_every and steps % self.laser_every == 0:
            self.sink.write(topics.LASER_SCAN, now_ns,
                            self.head.scan(sim.state_time_ns)[TCPROS_PREFIX_BYTES:])
        self.count = k + 1
        if self.count == BLOCK_STEPS:
            self.write_steps()

    def write_steps(self) -> None:
        """Turn the kept steps into messages (SimMessages' selection) and queue them."""
        count, sink = self.count, self.sink
        if count:
            atlas = self.sim.atlas
            position, velocity, effort = (view[:count] for view in self.joint_views)
            position[:] = self.qpos[:count, atlas.qpos_adr]
            velocity[:] = self.qvel[:count, atlas.dof_adr]
            effort[:] = self.torque[:count]
            now_ns, sensed_ns = self.now_ns[:count], self.sensed_ns[:count]
            sink.write_rows(topics.JOINT_STATES, *self.joint_states.take(
                now_ns, step_stamp(topics.JOINT_STATES, now_ns, sensed_ns)))
            sensors = self.sensordata[:count]
            for topic, (block, selection) in self.sensor_blocks.items():
                to = selection.to
                floats = block.float_view(selection.float_offset, max(to) + 1)
                floats[:count, to] = sensors[:, selection.source]
                sink.write_rows(topic, *block.take(now_ns, step_stamp(topic, now_ns, sensed_ns)))
        sink.write_rows(topics.GROUND_TRUTH_ODOM, *self.odometry.take())
        self.count = 0
        sink.flush()


class OfflinePlayer:
    """The simulator, traj_yaml's commands and the recorder, on one sim clock; each step is
    the node's tick (stepping.Tick), in its order.

    Args:
        on_step: called with the simulator at the end of every step (after its messages).
        latency: each command delayed as a live run's delivery does.
        controller: gives the simulator each step's command, after the delayed commands
            due (an AtlasSimInterface session's recorded commands).
        interface: the AtlasSimInterface played with the run: its end_step ends each step,
            before on_step.
        score_dir: score the VRC course in the tick (stepping.CourseScoring): score.log
            there and /vrc_score in the bag; None: not scored.
    """

    def __init__(self, sim: AtlasSimulator, sink: BlockBagWriter,
                 on_step: StepHook | None = None, latency: CommandLatency | None = None,
                 controller: StepController | None = None,
                 interface: AtlasSimInterface | None = None,
                 score_dir: Path | None = None) -> None:
        self.sim = sim
        self.latency = latency
        self.latency_rng = default_rng(latency.seed if latency else 0)
        #: Delayed commands: (the step count at which each takes effect, its update).
        self.pending: list[tuple[int, CommandUpdate]] = []
        self.sink = sink
        self.on_step = on_step
        self.rows = _StepRows(sim, sink)
        self.write_steps = self.rows.write_steps
        self.steps = 0
        self.decoder = CommandDecoder()
        self.command = _command_wire(sim.gains)
        self.commands_sent = 0
        self._log_seq = 0
        types = sink.typestore.types
        self._string = types['std_msgs/msg/String']
        self._log = types['rosgraph_msgs/msg/Log']
        self._header = types['std_msgs/msg/Header']
        self._time = types['builtin_interfaces/msg/Time']
        self.controller = controller
        self.interface = interface
        self._score = types['atlas_msgs/msg/VRCScore']
        self.scoring = (CourseScoring(sim, score_dir, self._write_score)
                        if score_dir is not None else None)
        self.tick = Tick(sim, self, self._publish_step, self._end_step, score=self.scoring)

    def publish(self) -> None:
        """Keep what the simulator node sends after a step (or before the first)."""
        self.rows.publish(self.steps)

    def advance(self, duration_s: float) -> None:
        """Step and publish for `duration_s` of sim time (whole steps, rounded up)."""
        sim = self.sim
        until_ns = sim.sim_time_ns + int(round(duration_s * NS_PER_S))
        tick = self.tick
        try:
            while sim.sim_time_ns < until_ns:
                tick()
        except PhysicsDivergenceError as err:
            raise OfflineRunError(f'{err}; the live simulator would reset the robot here, '
                                  'an offline run stops') from None

    def before_step(self) -> None:
        """The tick's inputs: the delayed commands due, then the controller's."""
        if self.pending:
            self._deliver()
        if self.controller is not None:
            self.controller.before_step()

    def _publish_step(self) -> None:
        """The tick's state: the spindle's step, then what the node sends after the step,
        kept."""
        self.steps += 1
        self.rows.head.step()
        self.rows.publish(self.steps)

    def _end_step(self) -> None:
        """The tick's end of step: the interface's handover, then the run's hook."""
        if self.interface is not None:
            self.interface.end_step()
        if self.on_step is not None:
            self.on_step(self.sim)

    def _write_score(self, row: ScoreRow) -> None:
        """A row of the course's scoring into the bag's /vrc_score, as the node publishes it."""
        def stamp(ns: int) -> object:
            secs, nsecs = divmod(ns, NS_PER_S)
            return self._time(sec=secs, nanosec=nsecs)

        self.sink.write_message(topics.VRC_SCORE, self.sim.sim_time_ns, self._score(
            wall_time=stamp(row.wall_elapsed_ns), sim_time=stamp(row.sim_time_ns),
            wall_time_elapsed=stamp(row.wall_since_gate0_ns),
            sim_time_elapsed=stamp(row.sim_since_gate0_ns), completion_score=row.completion,
            falls=row.falls, message=row.message, task_type=row.task_type))

    def _deliver(self) -> None:
        """Apply the delayed commands due before this step, in order."""
        due = 0
        while due < len(self.pending) and self.pending[due][0] <= self.steps:
            due += 1
        if due:
            self.sim.receive_updates([update for _, update in self.pending[:due]])
            del self.pending[:due]

    def now_s(self) -> float:
        return self.sim.sim_time_ns / NS_PER_S

    # -- what the user and traj_yaml do ------------------------------------------------
    def write_config(self) -> None:
        self.sink.write_message(topics.SIM_CONFIG, self.sim.sim_time_ns,
                                self._string(data=self.sim.config().to_json()))

    def switch_mode(self, mode: ControlMode) -> None:
        self.sink.write_message(topics.CONTROL_MODE, self.sim.sim_time_ns,
                                self._string(data=mode.value))
        self.sim.set_mode(mode)

    def apply_input(self, item: SimInput) -> None:
        """A VRCPlugin input, applied and written to /atlas/sim_inputs as the node does
        (the sink needs a connection for that topic)."""
        self.sim.apply_input(item)
        self.sink.write_message(topics.SIM_INPUTS, self.sim.sim_time_ns,
                                self._string(data=self.sim.last_input_event().to_json()))

    def send(self, positions: np.ndarray) -> None:
        """One traj_yaml command: written to the bag, then decoded as the simulator does."""
        stamp_ns = self.sim.sim_time_ns
        self.command.arrays['position'][:] = positions
        raw = self.command.to_bytes(stamp_ns)[TCPROS_PREFIX_BYTES:]
        self.sink.write(topics.JOINT_COMMANDS, stamp_ns, raw)
        try:
            update = self.decoder.decode(raw)
        except CommandError as err:  # traj_yaml's commands are valid: a defect here
            raise OfflineRunError(f'the simulator refused an offline command: {err}') from err
        if self.latency is None:
            self.sim.receive_updates([update])
        else:  # applied by advance(), before the step it is due at
            delay = int(self.latency_rng.integers(self.latency.min_steps,
                                                  self.latency.max_steps + 1))
            after = self.pending[-1][0] if self.pending else 0
            self.pending.append((max(after, self.steps + delay), update))
        self.commands_sent += 1

    def log(self, text: str) -> None:
        """An INFO line on /rosout, as rospy.loginfo in traj_yaml."""
        stamp_ns = self.sim.sim_time_ns
        self._log_seq += 1
        secs, nsecs = divmod(stamp_ns, NS_PER_S)
        message = self._log(
            header=self._header(seq=self._log_seq, stamp=self._time(sec=secs, nanosec=nsecs),
                                frame_id=''),
            level=LOG_INFO, name=PLAYER_NODE, msg=text, file='offline_run.py',
            function='run_offline', line=0, topics=[topics.JOINT_COMMANDS, topics.ROSOUT])
        self.sink.write_message(topics.ROSOUT, stamp_ns, message)


def _offset_in(message: StampedWire, view: np.ndarray) -> int:
    """Byte offset of `view` (a wire.py field) in `message`'s serialization (no TCPROS prefix)."""
    base = np.frombuffer(message.buf, dtype=np.uint8).ctypes.data
    return view.ctypes.data - base - TCPROS_PREFIX_BYTES


def _command_wire(gains: Gains) -> JointCommandsWire:
    """traj_yaml's JointCommands (traj_yaml_node.build_command), laid out once."""
    command = JointCommandsWire([ATLAS_PREFIX + name for name in JOINT_NAMES])
    arrays = command.arrays
    arrays['kp_position'][:] = gains.p
    arrays['ki_position'][:] = gains.i
    arrays['kd_position'][:] = gains.d
    arrays['i_effort_min'][:] = 0.0 - gains.i_clamp  # 0.0 - x: no -0.0, as build_command
    arrays['i_effort_max'][:] = gains.i_clamp
    return command


def write_offline_bag(bag: Path, trajectory_file: str, name: str, waypoints: Sequence[Waypoint],
                      gains: Gains, settle_s: float, start_after_s: float,
                      world: OfflineWorld | None = None,
                      play_after_s: float = 0.0,
                      on_step: StepHook | None = None,
                      latency: CommandLatency | None = None, scans: bool = False) -> OfflineRun:
    """Simulate the run and write it to `bag` (a new file; see run_offline for the checks).

    `on_step`, if given, is called with the simulator after every step (and its messages):
    the sweep measures a run there, and applies its pushes, without reading the bag back.
    `latency`, if given, delays each command as a live run's delivery does (CommandLatency).
    `world`: the model, the start and the mud's damping (None: the flat world's, at the
    origin). `scans`: the head's laser scans too.
    """
    world = world or OfflineWorld()
    sim = AtlasSimulator(load_model(world.model_path), gains, start=world.start,
                         mud_damping=world.mud_damping)
    sink = open_offline_bag(bag, scans)
    # The run's time, without loading the model and the message types (fixed costs).
    started_s = time.perf_counter()
    try:
        player = OfflinePlayer(sim, sink, on_step, latency)
        player.write_config()
        player.publish()  # the initial state, before the first step, as the node does
        player.advance(start_after_s)
        player.switch_mode(ControlMode.USER)
        player.advance(play_after_s)
        player.log(trajectory_log_line(trajectory_file, name))
        player.log(playing_line(name, waypoints))
        run_trajectory(waypoints, sim.joint_positions, player.send, player.advance, player.log,
                       player.now_s)
        player.log(done_line(name))
        player.advance(settle_s)
        player.write_steps()
    finally:
        sink.close()
    return OfflineRun(bag, player.commands_sent, sim.sim_time_ns / NS_PER_S, player.steps,
                      time.perf_counter() - started_s)


def run_offline(trajectory_file: str, name: str, bag: Path | str,
                settle_s: float = DEFAULT_SETTLE_S,
                start_after_s: float = DEFAULT_START_AFTER_S,
                gains_file: Path = DEFAULT_GAINS_FILE,
                world: OfflineWorld | None = None,
                play_after_s: float = 0.0, scans: bool = False) -> OfflineRun:
    """Run trajectory `name` of `trajectory_file` offline into the bag `bag` (`scans`: with
    the head's laser scans, as a live run's bag has them).

    User mode starts `start_after_s` after spawn and the trajectory `play_after_s` later (a
    live traj_yaml.py starts a few seconds after the switch: to re-create a live run, give
    both from its bag). `world`: the model and start (None: the flat world at the origin).

    The bag is written under a temporary name beside `bag` and renamed when complete
    (replacing an existing file): a failed run leaves nothing.

    Raises:
        TrajectoryError, GainsError, ModelError, CourseError: bad inputs (checked before
            simulating).
        OfflineRunError: `bag`'s directory does not exist, or the physics diverged.
    """
    if world is not None:
        check_mud_damping(world.mud_damping)
    path = locate_trajectory_file(trajectory_file)
    waypoints = load_trajectory(path, name)
    gains = load_gains_yaml(gains_file)
    return write_whole(Path(bag), lambda partial: write_offline_bag(
        partial, os.path.abspath(path), name, waypoints, gains, settle_s, start_after_s,
        world, play_after_s, scans=scans))


def write_whole(target: Path, write: Callable[[Path], OfflineRun]) -> OfflineRun:
    """`write` the run to a temporary name beside `target`, renamed to it when complete
    (replacing an existing file): a failed run leaves nothing.

    Raises:
        OfflineRunError: `target`'s directory does not exist, it is a directory, or it
            cannot be written.
    """
    if not target.parent.is_dir():
        raise OfflineRunError(f'{target}: directory {target.parent} does not exist')
    if target.is_dir():
        raise OfflineRunError(f'{target} is a directory; give a .bag file name')
    partial = target.parent / f'.{target.name}.{os.getpid()}.partial'
    try:
        run = write(partial)
        os.replace(partial, target)
    except OSError as err:
        raise OfflineRunError(f'cannot write {target}: {err.strerror or err}') from err
    finally:
        partial.unlink(missing_ok=True)
    return OfflineRun(target, run.commands, run.sim_time_s, run.steps, run.wall_s)
