"""Offline runs: play a trajectory into the simulator without ROS, deterministically, to a bag.

`run_offline.py YAML_FILE NAME` does what `make demo` does (spawn, wait past the torso
pin, switch to User, play the trajectory with traj_yaml's schedule, settle) but in one
process, on the simulator's own clock, as fast as the machine steps it: no master, no
transport, no scheduling jitter, so two runs of the same inputs are identical.

Each piece is the live one: trajectory loading and validation (trajectory.py), the
schedule (schedule.run_trajectory), the commands traj_yaml sends (every field as
traj_yaml_node.build_command sets it), the simulator decoding them (commands.CommandDecoder)
and stepping (AtlasSimulator), its messages (sim_messages.SimMessages). The bag has the
topics, types, MD5 sums and header stamps of a recorded live run (/clock thinned to
CLOCK_PERIOD_NS), so every bag tool reads it as one.
"""

from __future__ import annotations

import argparse
import json
import os
import struct
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.typesys import get_types_from_msg

from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.analysis import analyze_bag
from tutorial_atlas_control.bags.reader import load_typestore
from tutorial_atlas_control.bags.report import short_summary
from tutorial_atlas_control.cli.convention import print_error
from tutorial_atlas_control.msgs.commands import CommandDecoder, CommandError
from tutorial_atlas_control.sim.controller import DEFAULT_GAINS_FILE, Gains, load_gains_yaml
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import ATLAS_PREFIX, JOINT_NAMES
from tutorial_atlas_control.trajectories.schedule import (
    done_line, playing_line, run_trajectory, trajectory_log_line)
from tutorial_atlas_control.msgs.sim_messages import TCPROS_PREFIX_BYTES, SimMessages
from tutorial_atlas_control.stepping.schedule import step_stamp, steps_between
from tutorial_atlas_control.sim.simulator import (
    AtlasSimulator, ControlMode, PhysicsDivergenceError)
from tutorial_atlas_control.trajectories.trajectory import (
    Waypoint, load_trajectory, locate_trajectory_file)
from tutorial_atlas_control.units import NS_PER_S
from tutorial_atlas_control.msgs.wire import JointCommandsWire, StampedWire, clock_bytes

__all__ = ['OfflineRunError', 'OfflineRun', 'main', 'run_offline', 'write_offline_bag']

PROG = 'run_offline.py'
#: Sim time (s) before the switch to User, as `make demo`: past the 1 s torso pin.
DEFAULT_START_AFTER_S = 1.5
#: Sim time (s) the robot is left alone after the last command, as `make demo`.
DEFAULT_SETTLE_S = 3.0
#: /clock is written every this many ns of sim time (the live simulator sends it every
#: step; nothing reads a bag's /clock at that rate, and it is a fifth of the records).
CLOCK_PERIOD_NS = 10_000_000
#: /ground_truth_odom's rate (Hz), the simulator's default (~odom_rate).
ODOM_RATE_HZ = 100.0
#: Who published what in a live run: the bag's connections name them as callers.
SIMULATOR_NODE = '/atlas_sim'
PLAYER_NODE = '/tutorial_atlas_control'
#: rosgraph_msgs/Log's INFO level.
LOG_INFO = 2
#: Bag chunk size (bytes): rosbag record's default.
CHUNK_BYTES = 768 * 1024

JOINT_COMMANDS_TYPE = 'osrf_msgs/msg/JointCommands'
#: tf2_msgs/TFMessage, field for field (its definition as Debian's ros-tf2-msgs ships it).
TF_TYPE = 'tf2_msgs/msg/TFMessage'
TF_MSG_DEFINITION = 'geometry_msgs/TransformStamped[] transforms'
#: Topic -> (type, publishing node, latched), as in a live run.
TOPIC_TYPES: dict[str, tuple[str, str, bool]] = {
    topics.SIM_CONFIG: ('std_msgs/msg/String', SIMULATOR_NODE, True),
    topics.CLOCK: ('rosgraph_msgs/msg/Clock', SIMULATOR_NODE, False),
    topics.JOINT_STATES: ('sensor_msgs/msg/JointState', SIMULATOR_NODE, False),
    topics.GROUND_TRUTH_ODOM: ('nav_msgs/msg/Odometry', SIMULATOR_NODE, False),
    topics.IMU: ('sensor_msgs/msg/Imu', SIMULATOR_NODE, False),
    topics.L_FOOT_CONTACT: ('geometry_msgs/msg/WrenchStamped', SIMULATOR_NODE, False),
    topics.R_FOOT_CONTACT: ('geometry_msgs/msg/WrenchStamped', SIMULATOR_NODE, False),
    topics.CONTROL_MODE: ('std_msgs/msg/String', PLAYER_NODE, True),
    topics.JOINT_COMMANDS: (JOINT_COMMANDS_TYPE, PLAYER_NODE, False),
    topics.ROSOUT: ('rosgraph_msgs/msg/Log', PLAYER_NODE, True),
    topics.TF: (TF_TYPE, SIMULATOR_NODE, False),
}


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


_U32 = struct.Struct('<I')
_TIME = struct.Struct('<II')


def _put_times(rows: np.ndarray, at: int, times_ns: np.ndarray) -> None:
    """Write ROS times (secs, nsecs as two uint32) at byte `at` of every row."""
    column = rows[:, at:at + 8].view('<u4')
    column[:, 0] = times_ns // NS_PER_S
    column[:, 1] = times_ns % NS_PER_S


class _RecordBlock:
    """Bag records of one topic whose messages all have the layout of one wire.py message.

    Rows are laid out once as whole bag records (record header, length, the message as
    the wire message holds it); the numbers of many steps are then written into them by
    numpy (float_view, or add() copying the wire message) and take() stamps the record
    times, Header.seq and Header.stamp of all rows at once.
    """

    def __init__(self, record_prefix: bytes, message: StampedWire, capacity: int) -> None:
        self.source = np.frombuffer(message.buf, dtype=np.uint8)[TCPROS_PREFIX_BYTES:]
        self.time_at = len(record_prefix)
        self.data_at = self.time_at + 8 + 4
        self.rows = np.zeros((capacity, self.data_at + len(self.source)), dtype=np.uint8)
        self.rows[:, :self.time_at] = np.frombuffer(record_prefix, dtype=np.uint8)
        self.rows[:, self.time_at + 8:self.data_at] = np.frombuffer(
            _U32.pack(len(self.source)), dtype=np.uint8)
        self.rows[:, self.data_at:] = self.source
        self.times_ns = np.empty(capacity, dtype=np.int64)
        self.stamps_ns = np.empty(capacity, dtype=np.int64)
        self.count = 0
        self.seq = 0

    def float_view(self, offset: int, count: int) -> np.ndarray:
        """The `count` float64s at byte `offset` of the message, every row: (rows, count)."""
        at = self.data_at + offset
        return self.rows[:, at:at + 8 * count].view('<f8')

    def add(self, time_ns: int, stamp_ns: int) -> None:
        """Queue the wire message as it is now, recorded at `time_ns`, stamped `stamp_ns`."""
        k = self.count
        self.rows[k, self.data_at:] = self.source
        self.times_ns[k] = time_ns
        self.stamps_ns[k] = stamp_ns
        self.count = k + 1

    def take(self, times_ns: np.ndarray | None = None,
             stamps_ns: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Stamp and return the first rows: those add()ed, or len(times_ns) filled in place."""
        if times_ns is None or stamps_ns is None:
            times_ns, stamps_ns = self.times_ns[:self.count], self.stamps_ns[:self.count]
        count = len(times_ns)
        rows = self.rows[:count]
        _put_times(rows, self.time_at, times_ns)
        rows[:, self.data_at:self.data_at + 4].view('<u4')[:, 0] = (
            self.seq + 1 + np.arange(count, dtype=np.uint32))
        _put_times(rows, self.data_at + 4, stamps_ns)
        self.seq += count
        self.count = 0
        return times_ns.copy(), rows


#: One entry of a bag chunk's index (IDXDATA): record time (secs, nsecs), offset in the chunk.
_INDEX_ENTRY = np.dtype([('sec', '<u4'), ('nsec', '<u4'), ('offset', '<u4')])


class _IndexEntries:
    """One connection's index entries in one chunk, kept as numpy blocks (len() = entries)."""

    def __init__(self) -> None:
        self.blocks: list[np.ndarray] = []
        self.count = 0

    def __len__(self) -> int:
        return self.count

    def add(self, times_ns: np.ndarray, offsets: np.ndarray) -> None:
        block = np.empty(len(times_ns), dtype=_INDEX_ENTRY)
        block['sec'], block['nsec'] = np.divmod(times_ns, NS_PER_S)
        block['offset'] = offsets
        self.blocks.append(block)
        self.count += len(block)

    def to_bytes(self) -> bytes:
        return b''.join(block.tobytes() for block in self.blocks)


def _writer_class() -> type:
    """rosbags' rosbag1 Writer, its chunk index kept and written by numpy.

    rosbags writes each index entry with its own struct calls when it closes a chunk
    (~1.5 us, four entries a step); the chunk layout (CHUNK, then one IDXDATA per
    connection) is rosbags' own, from its write_chunk (rosbags 0.11.9, requirements.txt).
    """
    from collections import defaultdict
    from io import BytesIO

    from rosbags.rosbag1.reader import RecordType
    from rosbags.rosbag1.writer import MAXSIZE, Header, WriteChunk, Writer

    def new_chunk() -> WriteChunk:
        return WriteChunk(BytesIO(), -1, MAXSIZE, 0, defaultdict(_IndexEntries))

    class IndexedWriter(Writer):  # type: ignore[misc]
        def __init__(self, path: Path) -> None:
            super().__init__(path)
            self.chunks = [new_chunk()]

        def write_chunk(self, chunk: WriteChunk) -> None:
            if (size := chunk.data.tell()) > 0:
                chunk.pos = self.bio.tell()
                header = Header()
                header.set_string('compression', self.compression_format)
                header.set_uint32('size', size)
                header.write(self.bio, RecordType.CHUNK)
                data = self.compressor(chunk.data.getvalue())
                self.bio.write(_U32.pack(len(data)))
                self.bio.write(data)
                for cid, entries in chunk.connections.items():
                    header = Header()
                    header.set_uint32('ver', 1)
                    header.set_uint32('conn', cid)
                    header.set_uint32('count', len(entries))
                    header.write(self.bio, RecordType.IDXDATA)
                    self.bio.write(_U32.pack(len(entries) * _INDEX_ENTRY.itemsize))
                    self.bio.write(entries.to_bytes())
                chunk.data.close()
                self.chunks.append(new_chunk())

    return IndexedWriter


class _BagSink:
    """A rosbags Writer with one connection per topic, written a block of steps at a time.

    rosbags' Writer.write builds each record header field by field (~6 us a message, four
    1 kHz topics: as much as a third of a physics step). Here a topic's record header is
    laid out once, the 1 kHz topics are stamped and appended by numpy a block at a time
    (_RecordBlock), and the rest as they come; all go into the writer's open chunk and its
    index (kept by numpy, _writer_class), so the writer closes and indexes the bag as its own.
    Within a chunk, records are grouped by topic (readers go by the index, in time order).
    """

    def __init__(self, path: Path) -> None:
        self.typestore = load_typestore()
        if JOINT_COMMANDS_TYPE not in self.typestore.fielddefs:
            raise OfflineRunError('cannot find osrf_msgs/JointCommands.msg (msg/osrf_msgs in '
                                  'the package): the commands could not be written')
        if TF_TYPE not in self.typestore.fielddefs:  # not in rosbags' Noetic store
            self.typestore.register(get_types_from_msg(TF_MSG_DEFINITION, TF_TYPE))
        self.writer = _writer_class()(path)
        self.writer.chunk_threshold = CHUNK_BYTES
        self.writer.open()
        self.connection_ids: dict[str, int] = {}
        self.prefixes: dict[str, bytes] = {}
        for topic, (msgtype, caller, latched) in TOPIC_TYPES.items():
            connection = self.writer.add_connection(
                topic, msgtype, typestore=self.typestore, callerid=caller,
                latching=1 if latched else None)
            self.connection_ids[topic] = connection.id
            # The record header as rosbags writes it: op=MSGDATA, conn=<id>, time=<8 bytes>.
            fields = [b'op=\x02', b'conn=' + _U32.pack(connection.id)]
            head = b''.join(_U32.pack(len(field)) + field for field in fields)
            size = len(head) + 4 + len(b'time=') + 8
            self.prefixes[topic] = (_U32.pack(size) + head + _U32.pack(len(b'time=') + 8)
                                    + b'time=')
        self._pending: list[tuple[str, int, bytes]] = []
        self._blocks: list[tuple[str, np.ndarray, bytes, int]] = []

    def block(self, topic: str, message: StampedWire) -> _RecordBlock:
        """Rows for BLOCK_STEPS records of `topic`, laid out like `message`."""
        return _RecordBlock(self.prefixes[topic], message, BLOCK_STEPS)

    def write_rows(self, topic: str, times_ns: np.ndarray, rows: np.ndarray) -> None:
        """Queue whole records (a _RecordBlock's take()) of `topic`."""
        if len(rows):
            self._blocks.append((topic, times_ns, rows.tobytes(), rows.shape[1]))

    def write(self, topic: str, time_ns: int, data: bytes) -> None:
        """Queue one message (its ROS 1 serialization, no length prefix) at bag time `time_ns`."""
        self._pending.append((topic, time_ns, data))

    def write_message(self, topic: str, time_ns: int, message: Any) -> None:
        """Serialize a rosbags message of the topic's type and queue it."""
        msgtype = TOPIC_TYPES[topic][0]
        self.write(topic, time_ns, bytes(self.typestore.serialize_ros1(message, msgtype)))

    def flush(self) -> None:
        """Append everything queued to the writer's open chunk; close the chunk when full."""
        writer = self.writer
        chunk = writer.chunks[-1]
        bio = chunk.data
        first_ns, last_ns = chunk.start, chunk.end
        for topic, time_ns, data in self._pending:
            chunk.connections[self.connection_ids[topic]].add(np.array([time_ns]),
                                                              np.array([bio.tell()]))
            bio.write(self.prefixes[topic] + _TIME.pack(*divmod(time_ns, NS_PER_S))
                      + _U32.pack(len(data)) + data)
            first_ns, last_ns = min(first_ns, time_ns), max(last_ns, time_ns)
        self._pending.clear()
        for topic, times_ns, records, width in self._blocks:
            start = bio.tell()
            bio.write(records)
            offsets = start + np.arange(len(times_ns), dtype=np.int64) * width
            chunk.connections[self.connection_ids[topic]].add(times_ns, offsets)
            first_ns, last_ns = min(first_ns, int(times_ns[0])), max(last_ns, int(times_ns[-1]))
        self._blocks.clear()
        chunk.start, chunk.end = first_ns, last_ns
        if bio.tell() > writer.chunk_threshold:
            writer.write_chunk(chunk)

    def close(self) -> None:
        self.flush()
        self.writer.close()


class _OfflinePlayer:
    """The simulator, traj_yaml's commands and the recorder, on one sim clock.

    After each step it keeps what the simulator node would publish as rows of numbers
    (qpos, qvel, torque, sensordata, stamps); every BLOCK_STEPS steps SimMessages' maps
    turn them into messages, all at once (write_steps).
    """

    def __init__(self, sim: AtlasSimulator, sink: _BagSink) -> None:
        self.sim = sim
        self.sink = sink
        self.messages = messages = SimMessages(sim)
        self.joint_states = sink.block(topics.JOINT_STATES, messages.joint_state_wire)
        self.odometry = sink.block(topics.GROUND_TRUTH_ODOM, messages.odometry_wire)
        self.sensor_blocks = {
            topics.IMU: (sink.block(topics.IMU, messages.imu_wire), 'imu', messages.imu_map),
            **{topic: (sink.block(topic, messages.contact_wires[side]), side,
                       messages.contact_maps[side])
               for topic, side in ((topics.L_FOOT_CONTACT, 'l'), (topics.R_FOOT_CONTACT, 'r'))}}
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
        self.steps = 0
        self.next_clock_ns = 0
        self.decoder = CommandDecoder()
        self.command = _command_wire(sim.gains)
        self.commands_sent = 0
        self._log_seq = 0
        types = sink.typestore.types
        self._string = types['std_msgs/msg/String']
        self._log = types['rosgraph_msgs/msg/Log']
        self._header = types['std_msgs/msg/Header']
        self._time = types['builtin_interfaces/msg/Time']

    # -- what the simulator publishes ---------------------------------------------------
    def publish(self) -> None:
        """Keep what the simulator node sends after a step, recorded at the time it sends it."""
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
        if self.steps % self.odom_every == 0:
            self.messages.fill_odometry()
            self.odometry.add(now_ns, sim.state_time_ns)
            self.sink.write(topics.TF, now_ns,
                            self.messages.pelvis_tf(sim.state_time_ns)[TCPROS_PREFIX_BYTES:])
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
            for topic, (block, name, (to, source)) in self.sensor_blocks.items():
                floats = block.float_view(self.messages.float_offsets[name], max(to) + 1)
                floats[:count, to] = sensors[:, source]
                sink.write_rows(topic, *block.take(now_ns, step_stamp(topic, now_ns, sensed_ns)))
        sink.write_rows(topics.GROUND_TRUTH_ODOM, *self.odometry.take())
        self.count = 0
        sink.flush()

    def advance(self, duration_s: float) -> None:
        """Step and publish for `duration_s` of sim time (whole steps, rounded up)."""
        sim = self.sim
        until_ns = sim.sim_time_ns + int(round(duration_s * NS_PER_S))
        step, publish = sim.step, self.publish
        try:
            while sim.sim_time_ns < until_ns:
                step()
                self.steps += 1
                publish()
        except PhysicsDivergenceError as err:
            raise OfflineRunError(f'{err}; the live simulator would reset the robot here, '
                                  'an offline run stops') from None

    def now_s(self) -> float:
        return self.sim.sim_time_ns / NS_PER_S

    # -- what the user and traj_yaml do ------------------------------------------------
    def write_config(self) -> None:
        self.sink.write_message(topics.SIM_CONFIG, self.sim.sim_time_ns,
                                self._string(data=json.dumps(self.sim.config())))

    def switch_mode(self, mode: ControlMode) -> None:
        self.sink.write_message(topics.CONTROL_MODE, self.sim.sim_time_ns,
                                self._string(data=mode.value))
        self.sim.set_mode(mode)

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
        self.sim.receive_updates([update])
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
                      model_path: Path = atlas_model.MODEL_PATH,
                      play_after_s: float = 0.0) -> OfflineRun:
    """Simulate the run and write it to `bag` (a new file; see run_offline for the checks)."""
    sim = AtlasSimulator(atlas_model.load_model(model_path), gains)
    sink = _BagSink(bag)
    # The run's time, without loading the model and the message types (fixed costs).
    started_s = time.perf_counter()
    try:
        player = _OfflinePlayer(sim, sink)
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
                model_path: Path = atlas_model.MODEL_PATH,
                play_after_s: float = 0.0) -> OfflineRun:
    """Run trajectory `name` of `trajectory_file` offline into the bag `bag`.

    User mode starts `start_after_s` after spawn and the trajectory `play_after_s` later (a
    live traj_yaml.py starts a few seconds after the switch: to re-create a live run, give
    both from its bag).

    The bag is written under a temporary name beside `bag` and renamed when complete
    (replacing an existing file): a failed run leaves nothing.

    Raises:
        TrajectoryError, GainsError, ModelError: bad inputs (checked before simulating).
        OfflineRunError: `bag`'s directory does not exist, or the physics diverged.
    """
    path = locate_trajectory_file(trajectory_file)
    waypoints = load_trajectory(path, name)
    gains = load_gains_yaml(gains_file)
    target = Path(bag)
    if not target.parent.is_dir():
        raise OfflineRunError(f'{target}: directory {target.parent} does not exist')
    if target.is_dir():
        raise OfflineRunError(f'{target} is a directory; give a .bag file name')
    partial = target.parent / f'.{target.name}.{os.getpid()}.partial'
    try:
        run = write_offline_bag(partial, os.path.abspath(path), name, waypoints, gains,
                                settle_s, start_after_s, model_path, play_after_s)
        os.replace(partial, target)
    except OSError as err:
        raise OfflineRunError(f'cannot write {target}: {err.strerror or err}') from err
    finally:
        partial.unlink(missing_ok=True)
    return OfflineRun(target, run.commands, run.sim_time_s, run.steps, run.wall_s)


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'{text!r} is not a number of seconds') from None
    if not (np.isfinite(value) and value >= 0.0):
        raise argparse.ArgumentTypeError(f'{text!r} must be a finite number of seconds >= 0')
    return value


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROG, description=(
            'Play trajectory NAME of YAML_FILE into the simulator without ROS, as `make demo` '
            'plays it live (User mode after --start-after s, traj_yaml\'s 50 Hz commands with '
            'the gains of --gains, then --settle s), deterministically and faster than real '
            'time. Prints the demo\'s summary; with --bag, also keeps the run as a ROS 1 bag '
            'that analyze_bag.py, replay_bag.py and rosbag read as a recorded run.'))
    parser.add_argument('trajectory_file', metavar='YAML_FILE', help='trajectory file')
    parser.add_argument('name', metavar='NAME', help='trajectory name in YAML_FILE')
    parser.add_argument('--bag', type=Path, metavar='OUT.bag',
                        help='write the run to this bag (replaced if it exists)')
    parser.add_argument('--settle', type=_seconds, default=DEFAULT_SETTLE_S, metavar='S',
                        help='sim time after the last command (default: %(default)g)')
    parser.add_argument('--play-after', type=_seconds, default=0.0, metavar='S',
                        help='sim time between the switch to User and the first command '
                             '(default: 0; a live traj_yaml.py starts a few seconds after)')
    parser.add_argument('--start-after', type=_seconds, default=DEFAULT_START_AFTER_S,
                        metavar='S', help='sim time from spawn to User mode and the first '
                        'command (default: %(default)g; the torso is pinned for 1 s)')
    parser.add_argument('--gains', type=Path, default=DEFAULT_GAINS_FILE, metavar='FILE',
                        help='controller gains YAML (default: config/atlas_controller.yaml)')
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """The command line; returns the exit status (1: bad input or failed run, nothing written)."""
    args = build_parser().parse_args(argv)
    try:
        with tempfile.TemporaryDirectory(prefix='tac_offline_') as scratch:
            # Without --bag the summary is read from a bag that is deleted afterwards.
            bag = args.bag if args.bag is not None else Path(scratch) / f'{args.name}.bag'
            run = run_offline(args.trajectory_file, args.name, bag, args.settle,
                              args.start_after, args.gains, play_after_s=args.play_after)
            analysis = analyze_bag(run.bag)
    except AtlasControlError as err:
        print_error(PROG, err)
        return 1
    print(f'offline: {args.name}: {run.commands} commands, {run.sim_time_s:.3f} s of sim time '
          f'in {run.wall_s:.2f} s ({run.real_time_factor:.1f}x real time)')
    print(short_summary(analysis))
    if args.bag is not None:
        print(f'bag:   {run.bag}')
    return 0
