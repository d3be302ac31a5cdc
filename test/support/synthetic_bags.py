"""Write synthetic ROS 1 bags with rosbags, shaped like the simulator's recordings.

The unit tests' bags and the benchmark's 60 s run bag (bench/offline.py), with no
simulator and no ROS installation: both import them from test/support.

Tests describe a run as a list of :class:`Record` (topic, ROS 1 type, bag time, message)
built with the helpers below and write it with :func:`write_bag`. Times are sim time in
seconds; bag record time equals the header stamp, as with ``/use_sim_time`` true.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable, Sequence

import numpy as np
from rosbags.rosbag1 import Writer

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.typestore import load_typestore, rosbags_msgtype
from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.trajectories.schedule import trajectory_log_line
from tutorial_atlas_control.units import NS_PER_S

#: ROS 1 Noetic's types with the package's osrf_msgs/JointCommands (bags.typestore).
TYPESTORE = load_typestore()


def _type(msgtype: str) -> Any:
    return TYPESTORE.types[rosbags_msgtype(msgtype)]


def _time(t_s: float) -> Any:
    stamp_ns = round(t_s * NS_PER_S)
    return _type('builtin_interfaces/Time')(sec=stamp_ns // NS_PER_S, nanosec=stamp_ns % NS_PER_S)


def _header(t_s: float, frame_id: str = '', seq: int = 0) -> Any:
    return _type('std_msgs/Header')(seq=seq, stamp=_time(t_s), frame_id=frame_id)


def _f64(values: Sequence[float] | np.ndarray | None) -> np.ndarray:
    return np.asarray([] if values is None else values, dtype=np.float64)


@dataclass(frozen=True)
class Record:
    """One message to write: topic, ROS 1 type ('pkg/Name'), bag time (s), message."""

    topic: str
    msgtype: str
    t_s: float
    message: Any


def joint_state(t_s: float, position: Sequence[float] | np.ndarray,
                velocity: Sequence[float] | np.ndarray | None = None,
                effort: Sequence[float] | np.ndarray | None = None,
                names: Sequence[str] = JOINT_NAMES, seq: int = 0) -> Record:
    """A /atlas/joint_states message stamped `t_s`; velocity/effort default to zeros."""
    count = len(names)
    msg = _type('sensor_msgs/JointState')(
        header=_header(t_s, seq=seq), name=list(names), position=_f64(position),
        velocity=_f64(np.zeros(count) if velocity is None else velocity),
        effort=_f64(np.zeros(count) if effort is None else effort))
    return Record('/atlas/joint_states', 'sensor_msgs/JointState', t_s, msg)


def joint_commands(t_s: float, position: Sequence[float] | np.ndarray,
                   names: Sequence[str] = (), stamp_s: float | None = None) -> Record:
    """A /atlas/joint_commands message; `names` empty means tutorial order.

    `stamp_s` overrides the header stamp (default `t_s`); 0 models an unstamped command.
    """
    count = len(position)
    zeros = np.zeros(count)
    msg = _type('osrf_msgs/JointCommands')(
        header=_header(t_s if stamp_s is None else stamp_s), name=list(names),
        position=_f64(position), velocity=_f64(zeros), effort=_f64(zeros),
        kp_position=_f64(zeros), ki_position=_f64(zeros), kd_position=_f64(zeros),
        kp_velocity=_f64(zeros), i_effort_min=_f64(zeros), i_effort_max=_f64(zeros))
    return Record('/atlas/joint_commands', 'osrf_msgs/JointCommands', t_s, msg)


def odometry(t_s: float, z_m: float, x_m: float = 0.0, y_m: float = 0.0,
             vz_m_s: float = 0.0) -> Record:
    """A /ground_truth_odom message with the pelvis at (x, y, z), identity orientation."""
    geo = _type
    pose = geo('geometry_msgs/PoseWithCovariance')(
        pose=geo('geometry_msgs/Pose')(
            position=geo('geometry_msgs/Point')(x=x_m, y=y_m, z=z_m),
            orientation=geo('geometry_msgs/Quaternion')(x=0.0, y=0.0, z=0.0, w=1.0)),
        covariance=np.zeros(36))
    twist = geo('geometry_msgs/TwistWithCovariance')(
        twist=geo('geometry_msgs/Twist')(
            linear=geo('geometry_msgs/Vector3')(x=0.0, y=0.0, z=vz_m_s),
            angular=geo('geometry_msgs/Vector3')(x=0.0, y=0.0, z=0.0)),
        covariance=np.zeros(36))
    msg = _type('nav_msgs/Odometry')(
        header=_header(t_s, frame_id='world'), child_frame_id='pelvis', pose=pose, twist=twist)
    return Record('/ground_truth_odom', 'nav_msgs/Odometry', t_s, msg)


def control_mode(t_s: float, mode: str) -> Record:
    """A /atlas/control_mode message (std_msgs/String, no header) recorded at `t_s`."""
    msg = _type('std_msgs/String')(data=mode)
    return Record('/atlas/control_mode', 'std_msgs/String', t_s, msg)


def rosout(t_s: float, text: str, node: str = '/tutorial_atlas_control') -> Record:
    """An INFO line on /rosout (rosgraph_msgs/Log) from `node`."""
    msg = _type('rosgraph_msgs/Log')(header=_header(t_s), level=2, name=node, msg=text,
                                     file='test.py', function='test', line=1, topics=[])
    return Record('/rosout', 'rosgraph_msgs/Log', t_s, msg)


def clock(t_s: float) -> Record:
    """A /clock message."""
    msg = _type('rosgraph_msgs/Clock')(clock=_time(t_s))
    return Record('/clock', 'rosgraph_msgs/Clock', t_s, msg)


def imu(t_s: float) -> Record:
    """A /atlas/imu message at rest."""
    geo = _type
    msg = _type('sensor_msgs/Imu')(
        header=_header(t_s, frame_id='imu_link'),
        orientation=geo('geometry_msgs/Quaternion')(x=0.0, y=0.0, z=0.0, w=1.0),
        orientation_covariance=np.zeros(9),
        angular_velocity=geo('geometry_msgs/Vector3')(x=0.0, y=0.0, z=0.0),
        angular_velocity_covariance=np.zeros(9),
        linear_acceleration=geo('geometry_msgs/Vector3')(x=0.0, y=0.0, z=9.81),
        linear_acceleration_covariance=np.zeros(9))
    return Record('/atlas/imu', 'sensor_msgs/Imu', t_s, msg)


def foot_contact(t_s: float, side: str, fz_n: float = 450.0) -> Record:
    """A /atlas/{l,r}_foot_contact message."""
    geo = _type
    msg = _type('geometry_msgs/WrenchStamped')(
        header=_header(t_s, frame_id=f'{side}_foot'),
        wrench=geo('geometry_msgs/Wrench')(
            force=geo('geometry_msgs/Vector3')(x=0.0, y=0.0, z=fz_n),
            torque=geo('geometry_msgs/Vector3')(x=0.0, y=0.0, z=0.0)))
    topic = f'/atlas/{side}_foot_contact'
    return Record(topic, topics.MSG_TYPES[topic], t_s, msg)


def write_bag(path: Path | str, records: Iterable[Record], *,
              compression: str | None = None, chunk_bytes: int | None = None,
              in_given_order: bool = False) -> Path:
    """Write `records` (any order; sorted by time, stably) to a new ROS 1 bag at `path`.

    `compression` is None, 'bz2' or 'lz4' (chunk compression, as `rosbag record -j/--lz4`);
    `chunk_bytes` overrides the chunk size (default 1 MiB) to get many chunks;
    `in_given_order` writes the records as given (a run whose sim time goes back).
    """
    path = Path(path)
    records = list(records)
    ordered = records if in_given_order else sorted(records, key=lambda record: record.t_s)
    writer = Writer(path)
    if chunk_bytes is not None:
        writer.chunk_threshold = chunk_bytes
    if compression:
        writer.set_compression(Writer.CompressionFormat[compression.upper()])
    with writer:
        connections: dict[str, Any] = {}
        for record in ordered:
            connection = connections.get(record.topic)
            if connection is None:
                connection = writer.add_connection(
                    record.topic, rosbags_msgtype(record.msgtype), typestore=TYPESTORE)
                connections[record.topic] = connection
            data = TYPESTORE.serialize_ros1(record.message, rosbags_msgtype(record.msgtype))
            writer.write(connection, round(record.t_s * NS_PER_S), data)
    return path


#: Pelvis height while standing (m).
STANDING_HEIGHT_M = 0.93


def run_records(duration_s: float = 60.0, *, state_period_s: float = 0.001,
                odom_period_s: float = 0.01, command_period_s: float = 0.02,
                fall_time_s: float | None = None, with_imu: bool = True) -> list[Record]:
    """Records resembling a simulator run: states at 1 kHz, odom 100 Hz, commands 50 Hz.

    The tutorial's arm swing is commanded on l_arm_shx/r_arm_shx (sinusoid, 0.5 rad) and
    measured with a 10 ms lag; all other joints hold 0. Modes: Stand, then User at 1 s.
    With `fall_time_s`, the pelvis drops linearly from standing height to 0.2 m over 1 s.
    """
    records: list[Record] = [control_mode(0.0, 'Stand'), control_mode(1.0, 'User')]
    shx = (JOINT_NAMES.index('l_arm_shx'), JOINT_NAMES.index('r_arm_shx'))

    def swing(t_s: float) -> float:
        return 0.5 * math.sin(2 * math.pi * 0.5 * max(t_s - 1.0, 0.0))

    steps = round(duration_s / state_period_s)
    for step in range(steps):
        t_s = step * state_period_s
        position = np.zeros(NUM_JOINTS)
        position[list(shx)] = swing(t_s - 0.01)
        records.append(joint_state(t_s, position, seq=step))
        records.append(clock(t_s))
        if with_imu:
            records.append(imu(t_s))
    for step in range(round(duration_s / odom_period_s)):
        t_s = step * odom_period_s
        z_m = STANDING_HEIGHT_M
        if fall_time_s is not None and t_s > fall_time_s:
            z_m = max(0.2, STANDING_HEIGHT_M - (t_s - fall_time_s) * (STANDING_HEIGHT_M - 0.2))
        records.append(odometry(t_s, z_m))
        records.append(foot_contact(t_s, 'l'))
        records.append(foot_contact(t_s, 'r'))
    for step in range(round(duration_s / command_period_s)):
        t_s = step * command_period_s + 0.0005
        position = np.zeros(NUM_JOINTS)
        position[list(shx)] = swing(t_s)
        records.append(joint_commands(t_s, position))
    return records


def write_run_bag(path: Path | str, duration_s: float = 60.0, **kwargs: Any) -> Path:
    """Write :func:`run_records` to `path` (the 60 s default is the speed benchmark)."""
    return write_bag(path, run_records(duration_s, **kwargs))

def sim_config(t_s: float, last_reset_s: float, time_to_unpin_s: float = 1.0) -> Record:
    """A /atlas/sim_config message (as the simulator publishes at start and on resets)."""
    text = json.dumps({'model_file': 'atlas_v1.xml', 'model_sha1': None, 'timestep': 0.001,
                       'time_to_unpin': time_to_unpin_s, 'last_reset_time': last_reset_s})
    return Record(topics.SIM_CONFIG, 'std_msgs/String', t_s, _type('std_msgs/String')(data=text))


@dataclass(frozen=True)
class TrySpec:
    """One try of :func:`tries_records`: how it began, what was played, when it fell.

    `reset`: None (the first try), 'reset_world' (sim time goes on) or 'reset_simulation'
    (sim time back to 0). Times are seconds from the try's start.
    """

    reset: str | None
    trajectory: str
    duration_s: float = 6.0
    first_command_s: float = 1.0
    commands_s: float = 2.0
    fall_s: float | None = None
    command_period_s: float = 0.02


def _try_records(spec: TrySpec, start_s: float, first: bool, state_period_s: float,
                 file: str) -> list[Record]:
    """One try's records from sim time `start_s`, in time order."""
    records = [sim_config(start_s + (0.0005 if first else 0.0002), 0.0 if first else start_s)]
    if first:
        records.append(control_mode(start_s + 0.5, 'User'))
    shx = JOINT_NAMES.index('l_arm_shx')
    first_s = start_s + spec.first_command_s
    records.append(rosout(first_s - 0.01, trajectory_log_line(file, spec.trajectory),
                          node='/traj_yaml'))
    for step in range(round(spec.commands_s / spec.command_period_s)):
        t_s = first_s + step * spec.command_period_s
        records.append(joint_commands(t_s, _with_joint(shx, 0.1 * step * spec.command_period_s)))
    for step in range(1, round(spec.duration_s / state_period_s)):
        t_s = start_s + step * state_period_s
        held = min(max(t_s - 0.01 - first_s, 0.0), spec.commands_s - spec.command_period_s)
        records.append(joint_state(t_s, _with_joint(shx, 0.1 * held), seq=step))
        records.append(clock(t_s))
        z_m = STANDING_HEIGHT_M
        if spec.fall_s is not None and t_s - start_s > spec.fall_s:
            z_m = max(0.2, STANDING_HEIGHT_M - (t_s - start_s - spec.fall_s))
        records.append(odometry(t_s, z_m))
    return sorted(records, key=lambda record: record.t_s)


def tries_records(specs: Sequence[TrySpec], state_period_s: float = 0.01,
                  file: str = 'Traj_data2.yaml') -> list[Record]:
    """A launch with several tries, in record order (write with `in_given_order=True`).

    States, /clock and odometry every `state_period_s`; commands on l_arm_shx (a ramp of
    0.1 rad/s) from each try's `first_command_s`, measured 10 ms late; the player's start
    line on /rosout just before; /atlas/sim_config at the start and after each reset; User
    mode from 0.5 s of the first try.
    """
    records: list[Record] = []
    start_s = 0.0
    for number, spec in enumerate(specs):
        if spec.reset == 'reset_simulation':
            start_s = 0.0
        records += _try_records(spec, start_s, number == 0, state_period_s, file)
        start_s += spec.duration_s
    return records


def _with_joint(index: int, value: float) -> np.ndarray:
    position = np.zeros(NUM_JOINTS)
    position[index] = value
    return position


def tracking_records(names_style: str) -> list[Record]:
    """Commands of l_arm_elx: 0.2 at 0.02 s, 0.4 at 0.07 s; measured 0.25 throughout.

    States every 10 ms from 0.00 s: the two before the first command do not count.
    `names_style`: bare, prefixed (atlas::), empty (tutorial order), subset (one joint).
    Expected errors (command - measured): -0.05 five times, +0.15 five times.
    """
    full = {'bare': list(JOINT_NAMES), 'prefixed': [f'atlas::{n}' for n in JOINT_NAMES],
            'empty': []}
    elx = JOINT_NAMES.index('l_arm_elx')
    records = [clock(0.0)]
    for t_s, value in ((0.02, 0.2), (0.07, 0.4)):
        if names_style == 'subset':
            records.append(joint_commands(t_s, [value], names=['atlas::l_arm_elx']))
        else:
            records.append(joint_commands(t_s, _with_joint(elx, value), names=full[names_style]))
    records += [joint_state(t_s, _with_joint(elx, 0.25))
                for t_s in np.round(0.02 + np.arange(-2, 10) * 0.01, 6)]
    return records


def unindexed_copy(source: Path, target: Path) -> Path:
    """What an interrupted `rosbag record` leaves: index_pos=0 in the bag header."""
    raw = bytearray(source.read_bytes())
    at = raw.index(b'index_pos=') + len(b'index_pos=')
    raw[at:at + 8] = bytes(8)
    target.write_bytes(bytes(raw))
    return target

