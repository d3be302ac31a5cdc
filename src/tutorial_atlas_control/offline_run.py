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
import os
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from tutorial_atlas_control import model as atlas_model
from tutorial_atlas_control import topics
from tutorial_atlas_control.commands import CommandDecoder, CommandError
from tutorial_atlas_control.controller import Gains, load_gains_yaml
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import ATLAS_PREFIX, JOINT_NAMES
from tutorial_atlas_control.schedule import run_trajectory, trajectory_log_line
from tutorial_atlas_control.sim_messages import TCPROS_PREFIX_BYTES, SimMessages
from tutorial_atlas_control.simulator import (
    AtlasSimulator, ControlMode, PhysicsDivergenceError)
from tutorial_atlas_control.trajectory import (
    Waypoint, load_trajectory, resolve_trajectory_file, sample_count)
from tutorial_atlas_control.units import NS_PER_S
from tutorial_atlas_control.wire import JointCommandsWire, clock_bytes

__all__ = ['OfflineRunError', 'OfflineRun', 'main', 'run_offline', 'write_offline_bag']

PROG = 'run_offline.py'
PACKAGE_DIR = Path(__file__).resolve().parents[2]
GAINS_FILE = PACKAGE_DIR / 'config' / 'atlas_controller.yaml'
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


class _BagSink:
    """A rosbags Writer with one connection per topic and a cheap write of raw bytes.

    rosbags' Writer.write builds each record header field by field (a dict, an f-string
    and a struct per field, ~6 us): four times a step, more than the serializing. Here
    the header of a topic's records is laid out once; a write packs the time into it and
    appends to the writer's open chunk, keeping the writer's own chunk index, so the
    writer closes, indexes and compresses the bag as its own.
    """

    def __init__(self, path: Path) -> None:
        import struct

        from rosbags.rosbag1 import Writer

        from tutorial_atlas_control.bag_analysis import load_typestore

        self.typestore = load_typestore()
        if JOINT_COMMANDS_TYPE not in self.typestore.fielddefs:
            raise OfflineRunError('cannot find osrf_msgs/JointCommands.msg (msg/osrf_msgs in '
                                  'the package): the commands could not be written')
        self.writer = Writer(path)
        self.writer.chunk_threshold = CHUNK_BYTES
        self.writer.open()
        self.connections: dict[str, Any] = {}
        self._headers: dict[str, tuple[bytes, bytes]] = {}
        self._time = struct.Struct('<II')
        self._u32 = struct.Struct('<I')
        for topic, (msgtype, caller, latched) in TOPIC_TYPES.items():
            connection = self.writer.add_connection(
                topic, msgtype, typestore=self.typestore, callerid=caller,
                latching=1 if latched else None)
            self.connections[topic] = connection
            # The record header as rosbags writes it: op=MSGDATA, conn=<id>, time=<8 bytes>.
            fields = [b'op=\x02', b'conn=' + self._u32.pack(connection.id)]
            head = b''.join(self._u32.pack(len(f)) + f for f in fields)
            size = len(head) + 4 + len(b'time=') + 8
            self._headers[topic] = (self._u32.pack(size) + head
                                    + self._u32.pack(len(b'time=') + 8) + b'time=',
                                    connection.id)

    def write(self, topic: str, stamp_ns: int, data: bytes | memoryview) -> None:
        """Append one message (its ROS 1 serialization, no length prefix) at bag time `stamp_ns`."""
        prefix, connection_id = self._headers[topic]
        writer = self.writer
        chunk = writer.chunks[-1]
        bio = chunk.data
        chunk.connections[connection_id].append((stamp_ns, bio.tell()))
        if stamp_ns < chunk.start:
            chunk.start = stamp_ns
        if stamp_ns > chunk.end:
            chunk.end = stamp_ns
        secs, nsecs = divmod(stamp_ns, NS_PER_S)
        bio.write(prefix)
        bio.write(self._time.pack(secs, nsecs))
        bio.write(self._u32.pack(len(data)))
        bio.write(data)
        if bio.tell() > writer.chunk_threshold:
            writer.write_chunk(chunk)

    def write_message(self, topic: str, stamp_ns: int, message: Any) -> None:
        """Serialize a rosbags message of the topic's type and write it."""
        msgtype = TOPIC_TYPES[topic][0]
        self.write(topic, stamp_ns, self.typestore.serialize_ros1(message, msgtype))

    def close(self) -> None:
        self.writer.close()


class _OfflinePlayer:
    """The simulator, traj_yaml's commands and the recorder, on one sim clock."""

    def __init__(self, sim: AtlasSimulator, sink: _BagSink) -> None:
        self.sim = sim
        self.sink = sink
        self.messages = SimMessages(sim)
        self.odom_every = max(1, int(round(1.0 / (ODOM_RATE_HZ * sim.dt_s))))
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
        """What the simulator node sends after a step, written at the sim time it sends it."""
        sim, write, messages = self.sim, self.sink.write, self.messages
        now_ns = sim.sim_time_ns
        sensed_ns = sim.state_time_ns
        skip = TCPROS_PREFIX_BYTES
        if now_ns >= self.next_clock_ns:
            write(topics.CLOCK, now_ns, clock_bytes(now_ns)[skip:])
            self.next_clock_ns = now_ns + CLOCK_PERIOD_NS
        write(topics.JOINT_STATES, now_ns, memoryview(messages.joint_state(now_ns))[skip:])
        if self.steps % self.odom_every == 0:
            write(topics.GROUND_TRUTH_ODOM, now_ns, memoryview(messages.odometry(sensed_ns))[skip:])
        write(topics.IMU, now_ns, memoryview(messages.imu(sensed_ns))[skip:])
        write(topics.L_FOOT_CONTACT, now_ns, memoryview(messages.foot_contact('l', sensed_ns))[skip:])
        write(topics.R_FOOT_CONTACT, now_ns, memoryview(messages.foot_contact('r', sensed_ns))[skip:])

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
        import json
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
                      model_path: Path = atlas_model.MODEL_PATH) -> OfflineRun:
    """Simulate the run and write it to `bag` (a new file; see run_offline for the checks)."""
    started_s = time.perf_counter()
    sim = AtlasSimulator(atlas_model.load_model(model_path), gains, model_path=model_path)
    sink = _BagSink(bag)
    try:
        player = _OfflinePlayer(sim, sink)
        player.write_config()
        player.publish()  # the initial state, before the first step, as the node does
        player.advance(start_after_s)
        player.switch_mode(ControlMode.USER)
        total = sum(sample_count(waypoint.duration_s) for waypoint in waypoints)
        player.log(trajectory_log_line(trajectory_file, name))
        player.log(f"playing trajectory '{name}': {len(waypoints)} waypoints, "
                   f"{sum(w.duration_s for w in waypoints):g} s, {total} commands")
        run_trajectory(waypoints, sim.joint_positions, player.send, player.advance, player.log,
                       player.now_s)
        player.log(f"trajectory '{name}' done")
        player.advance(settle_s)
    finally:
        sink.close()
    return OfflineRun(bag, player.commands_sent, sim.sim_time_ns / NS_PER_S, player.steps,
                      time.perf_counter() - started_s)


def run_offline(trajectory_file: str, name: str, bag: Path | None,
                settle_s: float = DEFAULT_SETTLE_S,
                start_after_s: float = DEFAULT_START_AFTER_S,
                gains_file: Path = GAINS_FILE,
                model_path: Path = atlas_model.MODEL_PATH) -> OfflineRun:
    """Run trajectory `name` of `trajectory_file` offline into `bag` (None: a temporary bag).

    The bag is written under a temporary name beside `bag` and renamed when complete
    (replacing an existing file): a failed run leaves nothing.

    Raises:
        TrajectoryError, GainsError, ModelError: bad inputs (checked before simulating).
        OfflineRunError: `bag`'s directory does not exist, or the physics diverged.
    """
    path = resolve_trajectory_file(trajectory_file)
    waypoints = load_trajectory(path, name)
    gains = load_gains_yaml(gains_file)
    if bag is None:
        directory = Path(tempfile.mkdtemp(prefix='tac_offline_'))
        target = directory / f'{name}.bag'
    else:
        target = Path(bag)
        directory = target.parent
        if not directory.is_dir():
            raise OfflineRunError(f'{target}: directory {directory} does not exist')
        if target.is_dir():
            raise OfflineRunError(f'{target} is a directory; give a .bag file name')
    partial = directory / f'.{target.name}.{os.getpid()}.partial'
    try:
        run = write_offline_bag(partial, os.path.abspath(path), name, waypoints, gains,
                                settle_s, start_after_s, model_path)
        os.replace(partial, target)
    except OSError as err:
        raise OfflineRunError(f'cannot write {target}: {err.strerror or err}') from err
    finally:
        partial.unlink(missing_ok=True)
        if bag is None and not target.exists():
            directory.rmdir()
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
    parser.add_argument('--start-after', type=_seconds, default=DEFAULT_START_AFTER_S,
                        metavar='S', help='sim time from spawn to User mode and the first '
                        'command (default: %(default)g; the torso is pinned for 1 s)')
    parser.add_argument('--gains', type=Path, default=GAINS_FILE, metavar='FILE',
                        help='controller gains YAML (default: config/atlas_controller.yaml)')
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """The command line; returns the exit status (1: bad input or failed run, nothing written)."""
    args = build_parser().parse_args(argv)
    try:
        run = run_offline(args.trajectory_file, args.name, args.bag, args.settle,
                          args.start_after, args.gains)
        from tutorial_atlas_control.bag_analysis import analyze_bag
        from tutorial_atlas_control.demo import summary_text

        analysis = analyze_bag(run.bag)
        print(f'offline: {args.name}: {run.commands} commands, {run.sim_time_s:.3f} s of sim '
              f'time in {run.wall_s:.2f} s ({run.real_time_factor:.1f}x real time)')
        print(summary_text(analysis))
        if args.bag is not None:
            print(f'bag:   {run.bag}')
    except AtlasControlError as err:
        print(err, file=sys.stderr)  # one line, as traj_yaml.py
        return 1
    finally:
        if args.bag is None and 'run' in locals():
            import shutil
            shutil.rmtree(run.bag.parent, ignore_errors=True)
    return 0
