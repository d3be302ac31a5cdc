"""Read a recorded run (ROS 1 bag) into time series, without ROS.

The high-rate topics (`/atlas/joint_states` at 1 kHz, `/ground_truth_odom`) are parsed
straight from their ROS 1 wire bytes with numpy, because deserializing ~60,000 JointState
messages one by one takes seconds. That is done only when the connection's MD5 sum is the
standard one and every message has the same layout; otherwise, and always with
`read_bag(..., fast=False)`, messages go through a rosbags typestore built from the bag's
own message definitions.

Times: messages with a header are placed at their header stamp (sim time), others at
their bag record time (also sim time, since the simulator runs with /use_sim_time).
All times in :class:`BagData` are seconds from the bag's start on the *run timeline*: sim
time, except that after a `/gazebo/reset_simulation` (sim time back to 0) times go on
from where the run before it stopped, plus a gap (records.EPOCH_GAP_NS), so they only
rise; :meth:`BagData.sim_time_s` gives the sim time back.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.interfaces import Connection
from rosbags.rosbag1 import ReaderError

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.records import EPOCH_GAP_NS, BagRecords, open_bag
from tutorial_atlas_control.bags.run_log import PlayedTrajectory, trajectory_lines
from tutorial_atlas_control.bags.typestore import (
    JOINT_COMMANDS_TYPE,
    load_typestore,
)
from tutorial_atlas_control.errors import BagAnalysisError
from tutorial_atlas_control.fall_report import FALL_LINE_PREFIX, LoggedFall, parse_fall_line
from tutorial_atlas_control.joints import JOINT_INDEX, JOINT_NAMES, NUM_JOINTS, bare_joint_name
from tutorial_atlas_control.msgs import FieldCursor, parse_names_arrays
from tutorial_atlas_control.units import NS_PER_S

__all__ = [
    'BagData',
    'JointCommandSeries',
    'JointStateSeries',
    'PelvisSeries',
    'TopicSummary',
    'read_bag',
    'zero_order_hold',
]

JOINT_STATE_TYPE = 'sensor_msgs/msg/JointState'
ODOMETRY_TYPE = 'nav_msgs/msg/Odometry'
STRING_TYPE = 'std_msgs/msg/String'
LOG_TYPE = 'rosgraph_msgs/msg/Log'
#: MD5 sums of the layouts the hand-written parsers understand.
JOINT_STATE_MD5 = '3066dcd76a6cfaef579bd0f34173e9fd'
ODOMETRY_MD5 = 'cd5e73d190d741a2f92e81eda573aca7'
JOINT_COMMANDS_MD5 = 'f298c98f3e9c7aae9376ac19f73bfba3'

#: Header stamps further than this from bag record times (s) suggest mixed clocks.
_CLOCK_MISMATCH_S = 1.0
#: Nav_msgs/Odometry after the two strings: pose (7) + cov (36), twist (6) + cov (36).
_ODOM_FLOATS = 85


# ---------------------------------------------------------------------------- data


@dataclass(frozen=True)
class TopicSummary:
    """One topic: ROS 1 type ('pkg/Name'), message count, mean rate (Hz) or None."""

    msgtype: str
    count: int
    rate_hz: float | None


@dataclass(frozen=True)
class JointStateSeries:
    """Measured joint states; arrays are (samples, joints), NaN where not reported."""

    t_s: np.ndarray
    names: tuple[str, ...]
    position: np.ndarray
    velocity: np.ndarray
    effort: np.ndarray


@dataclass(frozen=True)
class JointCommandSeries:
    """Commanded positions per message, (messages, NUM_JOINTS) in tutorial order.

    `position` holds NaN for joints a message did not command; `held` carries each
    joint's last commanded value forward (zero-order hold), NaN before its first command.
    """

    t_s: np.ndarray
    position: np.ndarray
    held: np.ndarray


@dataclass(frozen=True)
class PelvisSeries:
    """Pelvis pose and twist in the world frame: position (m), quaternion xyzw, twist."""

    t_s: np.ndarray
    position_m: np.ndarray
    orientation_xyzw: np.ndarray
    linear_velocity_m_s: np.ndarray
    angular_velocity_rad_s: np.ndarray


@dataclass(frozen=True)
class BagData:
    """What :func:`read_bag` extracted; series are None when the topic is absent.

    `modes` are (time, mode) at each change of /atlas/control_mode; `sim_configs` are
    (time, JSON text) of every /atlas/sim_config message, which replay parses; `played`
    the trajectories players logged on /rosout (time, trajectory). `epoch_starts_s` are
    the times where sim time went back (reset_simulation), `epoch_shifts_s` what was added
    to each epoch's sim times (see the module docstring); `sim_inputs` the (time, JSON
    text) of /atlas/sim_inputs (the applied VRCPlugin inputs); `logged_falls` the
    (time, figures) of the simulator's fall lines on /rosout (fall_report).
    """

    path: Path
    start_time_s: float
    duration_s: float
    topics: dict[str, TopicSummary]
    joint_states: JointStateSeries | None
    commands: JointCommandSeries | None
    pelvis: PelvisSeries | None
    modes: list[tuple[float, str]]
    sim_configs: list[tuple[float, str]]
    warnings: list[str] = field(default_factory=list)
    played: list[tuple[float, PlayedTrajectory]] = field(default_factory=list)
    epoch_starts_s: list[float] = field(default_factory=list)
    epoch_shifts_s: list[float] = field(default_factory=lambda: [0.0])
    sim_inputs: list[tuple[float, str]] = field(default_factory=list)
    logged_falls: list[tuple[float, LoggedFall]] = field(default_factory=list)

    def epoch_at(self, t_s: float) -> int:
        """The epoch (0: before any rewind of sim time) time `t_s` falls in."""
        return int(np.searchsorted(self.epoch_starts_s, t_s, side='right'))

    def sim_time_s(self, t_s: float) -> float:
        """The sim time (s) of time `t_s` (s from the bag's start, run timeline)."""
        return self.start_time_s + t_s - self.epoch_shifts_s[self.epoch_at(t_s)]

    def run_time_s(self, sim_time_s: float, epoch: int) -> float:
        """Sim time `sim_time_s` of epoch `epoch` on the run timeline (s from bag start)."""
        return sim_time_s - self.start_time_s + self.epoch_shifts_s[epoch]


def _header_stamp_ns(msg: Any) -> int:
    """The header stamp (ns) of a message deserialized by rosbags."""
    return msg.header.stamp.sec * NS_PER_S + msg.header.stamp.nanosec


# ---------------------------------------------------------------------------- numpy parsers


def _uniform_rows(raws: list[bytes]) -> np.ndarray | None:
    """All messages as one (messages, bytes) uint8 array, or None if lengths differ."""
    lengths = np.fromiter(map(len, raws), dtype=np.int64, count=len(raws))
    if not len(raws) or np.any(lengths != lengths[0]):
        return None
    return np.frombuffer(b''.join(raws), dtype=np.uint8).reshape(len(raws), int(lengths[0]))


def _column(rows: np.ndarray, start: int, dtype: str, count: int) -> np.ndarray:
    """`count` values of `dtype` at byte `start` of every row, as (rows, count)."""
    width = np.dtype(dtype).itemsize
    block = np.ascontiguousarray(rows[:, start:start + width * count])
    return block.view(dtype).reshape(len(rows), count)


def _same_in_every_row(rows: np.ndarray, start: int, end: int) -> bool:
    return bool((rows[:, start:end] == rows[0, start:end]).all())


def _stamps_ns(rows: np.ndarray) -> np.ndarray:
    """Header stamps (ns) of uniform rows whose message starts with std_msgs/Header."""
    secs_nsecs = _column(rows, 4, '<u4', 2).astype(np.int64)
    return secs_nsecs[:, 0] * NS_PER_S + secs_nsecs[:, 1]


def _joint_states_fast(raws: list[bytes]) -> tuple[np.ndarray, list[str], list[np.ndarray]] | None:
    """Vectorized JointState parse, or None if the messages do not share one layout."""
    rows = _uniform_rows(raws)
    if rows is None:
        return None
    cursor = FieldCursor(raws[0])
    cursor.header_stamp_ns()
    names = cursor.strings()
    fixed_end = cursor.pos  # frame_id and names must be identical in every message
    starts = []
    for _ in range(3):
        starts.append(cursor.pos + 4)
        cursor.f64s()
    if cursor.pos != rows.shape[1] or not _same_in_every_row(rows, 12, fixed_end):
        return None
    if not all(_same_in_every_row(rows, start - 4, start) for start in starts):  # lengths
        return None
    arrays = [_column(rows, start, '<f8', len(names)) for start in starts]
    return _stamps_ns(rows), names, arrays


def _odometry_fast(raws: list[bytes]) -> tuple[np.ndarray, np.ndarray] | None:
    """Vectorized Odometry parse: (stamps (ns), the 85 pose/twist floats), or None."""
    rows = _uniform_rows(raws)
    if rows is None:
        return None
    cursor = FieldCursor(raws[0])
    cursor.header_stamp_ns()
    cursor.string()  # child_frame_id
    floats_at = cursor.pos
    if floats_at + 8 * _ODOM_FLOATS != rows.shape[1]:
        return None
    if not _same_in_every_row(rows, 12, floats_at):
        return None
    return _stamps_ns(rows), _column(rows, floats_at, '<f8', _ODOM_FLOATS)


# ---------------------------------------------------------------------------- times


def _stamps_or_bag_times(stamps_ns: np.ndarray, bag_times_ns: np.ndarray) -> np.ndarray:
    """Header stamps, with unset (zero) stamps replaced by the bag record time.

    For commands, which a user may publish unstamped (`rostopic pub`) between stamped ones.
    """
    return np.where(stamps_ns > 0, stamps_ns, bag_times_ns)


def _series_times(stamps_ns: np.ndarray, bag_times_ns: np.ndarray) -> np.ndarray:
    """Header stamps of a series its publisher stamps (the simulator's), else bag times.

    A zero stamp there is sim time 0, the initial state: atlas_recorder keeps what arrives
    before the first /clock and writes it at the first valid time (say 12 ms), so taking
    that bag time for it would put the state at t=0 after the one at t=1 ms.
    """
    return stamps_ns if stamps_ns.any() else bag_times_ns


def _clock_mismatch(stamps_ns: np.ndarray, bag_ns: np.ndarray) -> str | None:
    """A warning if header stamps and bag record times are far apart, else None."""
    stamped = stamps_ns > 0
    if not stamped.any():
        return None
    offset_s = float(np.median(np.abs(stamps_ns[stamped] - bag_ns[stamped]))) / NS_PER_S
    if offset_s <= _CLOCK_MISMATCH_S:
        return None
    return (f'{topics.JOINT_STATES} header stamps are {offset_s:.3g} s from their bag record '
            'times (was /use_sim_time false while recording?); times relative to bag start '
            'may be off.')


# ---------------------------------------------------------------------------- topics


@dataclass
class _Reading:
    """What every topic's reader needs: the open bag and the run-wide context."""

    records: BagRecords
    typestore: Any
    start_ns: int
    warnings: list[str]
    #: Whether hand-written parsers may be used (MD5 permitting); False: the typestore only.
    fast: bool

    def raw(self, connections: Sequence[Connection]) -> tuple[np.ndarray, list[bytes]]:
        return self.records.raw_messages(connections)

    def run_stamps(self, stamps_ns: np.ndarray, bag_ns: np.ndarray,
                   connections: Sequence[Connection], zero_unset: bool) -> np.ndarray:
        """Header stamps (sim time, ns) moved to the run timeline, as the bag times are.

        Each message keeps the epoch, of the one it was recorded in and its two neighbours,
        that puts its stamp nearest its record time: one stamped before a reset_simulation
        and recorded after it (or the other way round) keeps the epoch it was stamped in,
        and a starved recorder, whose clock lags the stamps, moves nothing (the
        neighbours' stamps are the previous epoch's length plus EPOCH_GAP_NS away, the
        lag a fraction of a second). `zero_unset`: a zero stamp means "not stamped"
        (commands) and stays 0, else it is sim time 0 (states).
        """
        shifts_ns = np.asarray(self.records.epoch_shifts_ns, dtype=np.int64)
        if len(shifts_ns) == 1:
            return stamps_ns
        epochs = self.records.epochs(connections)
        stamped = (stamps_ns > 0) | (not zero_unset)
        distance_ns = np.abs(stamps_ns + shifts_ns[epochs] - bag_ns)
        for neighbour in (epochs - 1, epochs + 1):
            neighbour = np.clip(neighbour, 0, len(shifts_ns) - 1)
            neighbour_ns = np.abs(stamps_ns + shifts_ns[neighbour] - bag_ns)
            nearer = stamped & (neighbour_ns < distance_ns)
            epochs = np.where(nearer, neighbour, epochs)
            distance_ns = np.where(nearer, neighbour_ns, distance_ns)
        shifted = stamps_ns + shifts_ns[epochs]
        return np.where(stamps_ns > 0, shifted, stamps_ns) if zero_unset else shifted

    def seconds(self, times_ns: np.ndarray) -> np.ndarray:
        """Times (ns) as seconds from the bag's start."""
        return (times_ns - self.start_ns) / NS_PER_S

    def parses(self, connections: Sequence[Connection], md5: str) -> bool:
        """Whether the hand-written parser for the layout with `md5` applies."""
        return self.fast and all(connection.digest == md5 for connection in connections)


def _joint_state_message(raw: bytes, parse: bool,
                         typestore: Any) -> tuple[int, list[str], list[np.ndarray]]:
    """(stamp (ns), bare names, [position, velocity, effort]) of one JointState."""
    if parse:
        stamp_ns, names, arrays = parse_names_arrays(raw, 3)
    else:
        msg = typestore.deserialize_ros1(raw, JOINT_STATE_TYPE)
        stamp_ns, names = _header_stamp_ns(msg), msg.name
        arrays = [msg.position, msg.velocity, msg.effort]
    names = [bare_joint_name(name) for name in names]
    # A nameless JointState lists joints in tutorial order.
    return stamp_ns, names or list(JOINT_NAMES[:len(arrays[0])]), arrays


def _column_union(name_lists: Sequence[Sequence[str]]) -> list[str]:
    """Joint names seen, tutorial order first, unknown names after in order of appearance."""
    seen = {name for names in name_lists for name in names}
    extra = []
    for names in name_lists:
        extra.extend(name for name in names if name not in JOINT_INDEX and name not in extra)
    return [name for name in JOINT_NAMES if name in seen] + extra


def _joint_states_per_message(raws: list[bytes], parse: bool, typestore: Any) -> tuple[
        np.ndarray, list[str], list[np.ndarray]]:
    """(stamps (ns), column names, [position, velocity, effort]) of messages of any layout."""
    parsed = [_joint_state_message(raw, parse, typestore) for raw in raws]
    names = _column_union([msg_names for _, msg_names, _ in parsed])
    column = {name: index for index, name in enumerate(names)}
    stamps_ns = np.array([stamp for stamp, _, _ in parsed], dtype=np.int64)
    tables = [np.full((len(parsed), len(names)), np.nan) for _ in range(3)]
    for row, (_, msg_names, arrays) in enumerate(parsed):
        for table, values in zip(tables, arrays):
            count = min(len(values), len(msg_names))
            table[row, [column[name] for name in msg_names[:count]]] = values[:count]
    return stamps_ns, names, tables


def _read_joint_states(reading: _Reading, connections: Sequence[Connection]) -> JointStateSeries:
    bag_ns, raws = reading.raw(connections)
    parse = reading.parses(connections, JOINT_STATE_MD5)
    fast = _joint_states_fast(raws) if parse else None
    if fast is not None:
        stamps_ns, names, arrays = fast
        names = [bare_joint_name(name) for name in names]
        if not names:  # a nameless JointState lists joints in tutorial order
            names = list(JOINT_NAMES[:arrays[0].shape[1]])
    else:
        stamps_ns, names, arrays = _joint_states_per_message(raws, parse, reading.typestore)
    if stamps_ns.any():
        stamps_ns = reading.run_stamps(stamps_ns, bag_ns, connections, zero_unset=False)
    warning = _clock_mismatch(stamps_ns, bag_ns)
    if warning:
        reading.warnings.append(warning)
    position, velocity, effort = arrays
    t_s = reading.seconds(_series_times(stamps_ns, bag_ns))
    if np.any(np.diff(t_s) < 0):  # only around a reset_simulation
        order = np.argsort(t_s, kind='stable')
        t_s, position, velocity, effort = (t_s[order], position[order], velocity[order],
                                           effort[order])
    return JointStateSeries(t_s, tuple(names), position, velocity, effort)


def _command_message(raw: bytes, parse: bool, typestore: Any) -> tuple[int, list[str], Any]:
    """(stamp (ns), names as sent, positions) of one JointCommands message."""
    if parse:
        stamp_ns, names, (values,) = parse_names_arrays(raw, 1)
        return stamp_ns, names, values
    msg = typestore.deserialize_ros1(raw, JOINT_COMMANDS_TYPE)
    return _header_stamp_ns(msg), msg.name, msg.position


def zero_order_hold(position: np.ndarray) -> np.ndarray:
    """Each joint's latest commanded value at every row (NaN = not commanded yet)."""
    latest = np.where(np.isnan(position), -1, np.arange(len(position))[:, None])
    latest = np.maximum.accumulate(latest, axis=0) if len(position) else latest
    return np.where(latest >= 0, position[np.maximum(latest, 0), np.arange(NUM_JOINTS)], np.nan)


def _read_commands(reading: _Reading, connections: Sequence[Connection]) -> JointCommandSeries:
    bag_ns, raws = reading.raw(connections)
    parse = reading.parses(connections, JOINT_COMMANDS_MD5)
    if not parse and JOINT_COMMANDS_TYPE not in reading.typestore.fielddefs:
        raise BagAnalysisError(
            'The bag has no definition of osrf_msgs/JointCommands and '
            'osrf_msgs/msg/JointCommands.msg was not found; cannot read {topics.JOINT_COMMANDS}.')
    position = np.full((len(raws), NUM_JOINTS), np.nan)
    stamps_ns = np.empty(len(raws), dtype=np.int64)
    unknown: set[str] = set()
    for row, raw in enumerate(raws):
        stamps_ns[row], names, values = _command_message(raw, parse, reading.typestore)
        names = [bare_joint_name(name) for name in names] or JOINT_NAMES
        for name, value in zip(names, values):
            index = JOINT_INDEX.get(name)
            if index is None:
                unknown.add(name)
            else:
                position[row, index] = value
    if unknown:
        reading.warnings.append(f'{topics.JOINT_COMMANDS} names unknown joints, ignored: '
                                f'{", ".join(sorted(unknown))}.')
    stamps_ns = reading.run_stamps(stamps_ns, bag_ns, connections, zero_unset=True)
    t_ns = _stamps_or_bag_times(stamps_ns, bag_ns)
    order = np.argsort(t_ns, kind='stable')
    return JointCommandSeries(reading.seconds(t_ns[order]), position[order],
                              zero_order_hold(position[order]))


def _odometry_per_message(raws: list[bytes], typestore: Any) -> tuple[np.ndarray, np.ndarray]:
    """(stamps (ns), the 85 floats with pose and twist filled in) through the typestore."""
    stamps_ns = np.empty(len(raws), dtype=np.int64)
    floats = np.empty((len(raws), _ODOM_FLOATS))
    for row, raw in enumerate(raws):
        msg = typestore.deserialize_ros1(raw, ODOMETRY_TYPE)
        stamps_ns[row] = _header_stamp_ns(msg)
        pose, twist = msg.pose.pose, msg.twist.twist
        floats[row, 0:7] = [pose.position.x, pose.position.y, pose.position.z,
                            pose.orientation.x, pose.orientation.y, pose.orientation.z,
                            pose.orientation.w]
        floats[row, 43:49] = [twist.linear.x, twist.linear.y, twist.linear.z,
                              twist.angular.x, twist.angular.y, twist.angular.z]
    return stamps_ns, floats


def _read_pelvis(reading: _Reading, connections: Sequence[Connection]) -> PelvisSeries:
    bag_ns, raws = reading.raw(connections)
    fast = _odometry_fast(raws) if reading.parses(connections, ODOMETRY_MD5) else None
    stamps_ns, floats = fast or _odometry_per_message(raws, reading.typestore)
    if stamps_ns.any():
        stamps_ns = reading.run_stamps(stamps_ns, bag_ns, connections, zero_unset=False)
    t_s = reading.seconds(_series_times(stamps_ns, bag_ns))
    if np.any(np.diff(t_s) < 0):  # only around a reset_simulation
        order = np.argsort(t_s, kind='stable')
        t_s, floats = t_s[order], floats[order]
    return PelvisSeries(t_s, floats[:, 0:3].copy(), floats[:, 3:7].copy(),
                        floats[:, 43:46].copy(), floats[:, 46:49].copy())


def _read_strings(reading: _Reading, connections: Sequence[Connection]) -> list[tuple[float, str]]:
    """(bag time, text) of every std_msgs/String on `connections`, in time order."""
    bag_ns, raws = reading.raw(connections)
    return [(float(t_s), reading.typestore.deserialize_ros1(raw, STRING_TYPE).data)
            for t_s, raw in zip(reading.seconds(bag_ns), raws)]


def _read_played(reading: _Reading,
                 connections: Sequence[Connection]) -> list[tuple[float, PlayedTrajectory]]:
    """(time, trajectory) of every trajectory a player logged on /rosout."""
    bag_ns, raws = reading.raw([c for c in connections if c.msgtype == LOG_TYPE])
    return trajectory_lines(reading.seconds(bag_ns).tolist(), bag_ns.tolist(), raws,
                            reading.typestore)


def _read_logged_falls(reading: _Reading,
                       connections: Sequence[Connection]) -> list[tuple[float, LoggedFall]]:
    """(time, figures) of every fall the simulator logged on /rosout (fall_report's line)."""
    bag_ns, raws = reading.raw([c for c in connections if c.msgtype == LOG_TYPE])
    marker = FALL_LINE_PREFIX.encode()
    found = []
    for t_s, raw in zip(reading.seconds(bag_ns).tolist(), raws):
        if marker not in raw:  # most lines are not falls: skip deserializing them
            continue
        fall = parse_fall_line(reading.typestore.deserialize_ros1(raw, LOG_TYPE).msg)
        if fall is not None:
            found.append((float(t_s), fall))
    return found


def _mode_changes(strings: list[tuple[float, str]]) -> list[tuple[float, str]]:
    """The control modes with repeats of the same mode dropped."""
    modes: list[tuple[float, str]] = []
    for t_s, mode in strings:
        if not modes or modes[-1][1] != mode:
            modes.append((t_s, mode))
    return modes


# ---------------------------------------------------------------------------- the bag


def _topic_summaries(records: BagRecords, by_topic: dict[str, list[Connection]]) -> tuple[
        dict[str, TopicSummary], int, int]:
    """Each topic's type, count and rate, and the bag's first and last times (ns)."""
    summaries: dict[str, TopicSummary] = {}
    start_ns = end_ns = None
    for topic in sorted(by_topic):
        connections = by_topic[topic]
        times_ns = records.times_ns(connections)
        rate_hz = None
        if len(times_ns):
            first_ns, last_ns = int(times_ns[0]), int(times_ns[-1])
            start_ns = first_ns if start_ns is None else min(start_ns, first_ns)
            end_ns = last_ns if end_ns is None else max(end_ns, last_ns)
            # Over the time recorded: without the gaps put between epochs (reset_simulation).
            gaps = sum(first_ns < epoch_ns < last_ns for epoch_ns in records.epoch_starts_ns)
            span_ns = last_ns - first_ns - gaps * EPOCH_GAP_NS
            if span_ns > 0:
                rate_hz = (len(times_ns) - 1) / (span_ns / NS_PER_S)
        # 'sensor_msgs/msg/JointState' -> 'sensor_msgs/JointState', as rosbag info shows it.
        msgtypes = sorted({c.msgtype.replace('/msg/', '/') for c in connections})
        summaries[topic] = TopicSummary(' | '.join(msgtypes), len(times_ns), rate_hz)
    start_ns = start_ns or 0
    return summaries, start_ns, end_ns or start_ns


#: The topics read_bag decodes: a wrong MD5 on one of them makes the bag unreadable.
_DECODED_TOPICS = (topics.JOINT_STATES, topics.JOINT_COMMANDS, topics.GROUND_TRUTH_ODOM,
                   topics.CONTROL_MODE, topics.SIM_CONFIG, topics.SIM_INPUTS, topics.ROSOUT)


def _check_digests(path: Path, typestore: Any, by_topic: dict[str, list[Connection]]) -> None:
    """Refuse a decoded topic whose MD5 is not its type's (as the typestore defines it: Noetic's,
    else the bag's own definition). Its messages would be decoded with a layout they may not
    have: numbers made up from other fields, or a failure half-way.

    Raises:
        BagAnalysisError: the first such connection, named with both MD5s.
    """
    for topic in _DECODED_TOPICS:
        for connection in by_topic.get(topic, ()):
            try:
                expected = typestore.generate_msgdef(connection.msgtype, ros_version=1)[1]
            except Exception:  # noqa: BLE001 - an unknown type is read (or refused) later
                continue
            if connection.digest and connection.digest != expected:
                ros1_type = connection.msgtype.replace('/msg/', '/')
                raise BagAnalysisError(
                    f'{path}: {topic} is recorded as {ros1_type} with MD5 {connection.digest}, '
                    f'but {ros1_type} has MD5 {expected}: the bag is damaged or was recorded '
                    'with another version of the message; it cannot be read.')


def _read_open_bag(path: Path, records: BagRecords, fast: bool) -> BagData:
    by_topic: dict[str, list[Connection]] = {}
    for connection in records.connections:
        by_topic.setdefault(connection.topic, []).append(connection)
    summaries, start_ns, end_ns = _topic_summaries(records, by_topic)
    reading = _Reading(records, load_typestore(records.connections), start_ns, [], fast)
    _check_digests(path, reading.typestore, by_topic)

    def series(topic: str, read: Any) -> Any:
        return read(reading, by_topic[topic]) if by_topic.get(topic) else None

    states = series(topics.JOINT_STATES, _read_joint_states)
    commands = series(topics.JOINT_COMMANDS, _read_commands)
    pelvis = series(topics.GROUND_TRUTH_ODOM, _read_pelvis)
    modes = _mode_changes(series(topics.CONTROL_MODE, _read_strings) or [])
    sim_configs = series(topics.SIM_CONFIG, _read_strings) or []
    sim_inputs = series(topics.SIM_INPUTS, _read_strings) or []
    played = series(topics.ROSOUT, _read_played) or []
    return BagData(path, start_ns / NS_PER_S, (end_ns - start_ns) / NS_PER_S, summaries,
                   states, commands, pelvis, modes, sim_configs, reading.warnings, played,
                   [(t_ns - start_ns) / NS_PER_S for t_ns in records.epoch_starts_ns],
                   [t_ns / NS_PER_S for t_ns in records.epoch_shifts_ns], sim_inputs,
                   series(topics.ROSOUT, _read_logged_falls) or [])


def read_bag(path: Path | str, fast: bool = True) -> BagData:
    """Read the topics the analysis and replay need from a ROS 1 bag, in one opening.

    Args:
        path: The .bag file.
        fast: Read with the numpy index and parsers (see records.py); False reads through
            rosbags' public API and typestore only, several times slower, same result, except
            that it cannot tell the runs before and after a reset_simulation apart.

    Returns:
        The extracted series; a series is None when its topic is not in the bag.

    Raises:
        BagAnalysisError: Missing file, not a bag, unindexed, damaged or empty bag.
    """
    path = Path(path)
    records = open_bag(path, fast)
    try:
        if not any(connection.msgcount for connection in records.connections):
            raise BagAnalysisError(
                f'{path} holds no message (a launch that stopped before its simulator was '
                'ready records nothing); give a bag of a run.')
        return _read_open_bag(path, records, fast)
    except (ReaderError, struct.error, ValueError, KeyError, IndexError,
            UnicodeDecodeError) as err:
        msg = f'Could not read {path}, a message is damaged ({type(err).__name__}: {err}).'
        raise BagAnalysisError(msg) from err
    finally:
        records.close()
