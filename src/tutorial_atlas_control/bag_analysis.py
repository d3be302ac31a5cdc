"""Read a recorded run (ROS 1 bag) and compute the tutorial's metrics, without ROS.

The bag is read with rosbags. The high-rate topics (`/atlas/joint_states`, 1 kHz, and
`/ground_truth_odom`) are parsed straight from their ROS 1 wire bytes with numpy,
because deserializing ~60,000 JointState messages one by one through the generic
deserializer takes seconds. The fast path is used only when the connection's MD5 sum is
the standard one and every message has the same layout; otherwise the messages are
deserialized with a rosbags typestore built from the bag's own message definitions.

Times: messages with a header are placed at their header stamp (sim time), others at
their bag record time (also sim time, since the simulator runs with /use_sim_time).
All times in :class:`BagData` and :class:`Analysis` are seconds from the bag's start.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import JOINT_INDEX, JOINT_NAMES, NUM_JOINTS, bare_joint_name
from tutorial_atlas_control.ros1_fields import FieldCursor, parse_names_arrays

__all__ = [
    'COMMAND_CHANGE_RAD',
    'EFFORT_LIMITS_NM',
    'EFFORT_LIMIT_TOLERANCE_NM',
    'FALL_HEIGHT_M',
    'MOVED_RANGE_RAD',
    'Analysis',
    'BagAnalysisError',
    'BagData',
    'JointCommandSeries',
    'JointStateSeries',
    'PelvisSeries',
    'TopicSummary',
    'analyze',
    'analyze_bag',
    'load_typestore',
    'read_bag',
]

# ---------------------------------------------------------------------------- constants

#: Pelvis height (m) below which the robot counts as fallen (standing is ~0.93 m).
FALL_HEIGHT_M = 0.5

#: A joint "moved" if its measured position spans more than this (rad) over the run...
MOVED_RANGE_RAD = 0.02
#: ...or if any commanded position differs from its first commanded value by more (rad).
COMMAND_CHANGE_RAD = 1e-6

#: A joint is at its effort limit when |effort| >= limit - this tolerance (N·m).
EFFORT_LIMIT_TOLERANCE_NM = 0.01

_LEG_LIMITS_NM = {'uhz': 110.0, 'mhx': 180.0, 'lhy': 260.0, 'kny': 220.0, 'uay': 220.0,
                  'lax': 90.0}
_ARM_LIMITS_NM = {'usy': 212.0, 'shx': 170.0, 'ely': 114.0, 'elx': 114.0, 'uwy': 114.0,
                  'mwx': 60.0}

#: Atlas v1 actuator effort limits (N·m) by bare joint name, in tutorial order
#: (the DRCSim atlas.urdf values; kept here so analysis needs no MuJoCo model).
EFFORT_LIMITS_NM: dict[str, float] = {
    'back_lbz': 124.016, 'back_mby': 206.843, 'back_ubx': 94.91, 'neck_ay': 5.0,
    **{f'{side}_leg_{joint}': limit for side in 'lr' for joint, limit in _LEG_LIMITS_NM.items()},
    **{f'{side}_arm_{joint}': limit for side in 'lr' for joint, limit in _ARM_LIMITS_NM.items()},
}
EFFORT_LIMITS_NM = {name: EFFORT_LIMITS_NM[name] for name in JOINT_NAMES}

JOINT_STATES_TOPIC = '/atlas/joint_states'
JOINT_COMMANDS_TOPIC = '/atlas/joint_commands'
ODOM_TOPIC = '/ground_truth_odom'
CONTROL_MODE_TOPIC = '/atlas/control_mode'

JOINT_COMMANDS_TYPE = 'osrf_msgs/msg/JointCommands'
#: MD5 sums of the layouts the fast parsers understand.
JOINT_STATE_MD5 = '3066dcd76a6cfaef579bd0f34173e9fd'
ODOMETRY_MD5 = 'cd5e73d190d741a2f92e81eda573aca7'
JOINT_COMMANDS_MD5 = 'f298c98f3e9c7aae9376ac19f73bfba3'

#: Where osrf_msgs/JointCommands.msg lives relative to this file in a source checkout.
_JOINT_COMMANDS_MSG_RELPATH = Path('msg') / 'osrf_msgs' / 'msg' / 'JointCommands.msg'

#: Header stamps further than this from bag record times (s) suggest mixed clocks.
_CLOCK_MISMATCH_S = 1.0

_NS_PER_S = 1_000_000_000
_BAG_MAGIC = b'#ROSBAG V2.0\n'
_U32 = struct.Struct('<I')
#: Nav_msgs/Odometry after the two strings: pose (7) + cov (36), twist (6) + cov (36).
_ODOM_FLOATS = 85


class BagAnalysisError(AtlasControlError):
    """The bag cannot be read or analyzed; the message says what to do about it."""


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
    """What :func:`read_bag` extracted; series are None when the topic is absent."""

    path: Path
    start_time_s: float
    duration_s: float
    topics: dict[str, TopicSummary]
    joint_states: JointStateSeries | None
    commands: JointCommandSeries | None
    pelvis: PelvisSeries | None
    modes: list[tuple[float, str]]
    warnings: list[str] = field(default_factory=list)


# ---------------------------------------------------------------------------- typestore


def _find_joint_commands_msg() -> Path | None:
    """Locate osrf_msgs/JointCommands.msg in a source checkout or a ROS install."""
    for parent in Path(__file__).resolve().parents:
        candidate = parent / _JOINT_COMMANDS_MSG_RELPATH
        if candidate.is_file():
            return candidate
    try:
        import rospkg  # noqa: PLC0415 - optional, only present in a ROS environment

        candidate = Path(rospkg.RosPack().get_path('osrf_msgs')) / 'msg' / 'JointCommands.msg'
    except Exception:  # noqa: BLE001 - any failure just means "not installed"
        return None
    return candidate if candidate.is_file() else None


def load_typestore(connections: Sequence[Any] = ()) -> Any:
    """Return a ROS 1 Noetic rosbags typestore that knows every type in `connections`.

    Types missing from the Noetic store are registered from the bag's own message
    definitions; osrf_msgs/JointCommands falls back to the package's .msg file.

    Raises:
        BagAnalysisError: A definition in the bag cannot be parsed or registered.
    """
    from rosbags.typesys import Stores, TypesysError, get_types_from_msg, get_typestore

    typestore = get_typestore(Stores.ROS1_NOETIC)
    for connection in connections:
        msgdef = getattr(connection.msgdef, 'data', '')
        if connection.msgtype in typestore.fielddefs or not msgdef:
            continue
        try:
            typestore.register(get_types_from_msg(msgdef, connection.msgtype))
        except TypesysError as err:
            msg = (f'Could not use the bag\'s definition of {connection.msgtype!r} on '
                   f'{connection.topic}: {err}')
            raise BagAnalysisError(msg) from err
    if JOINT_COMMANDS_TYPE not in typestore.fielddefs:
        msg_file = _find_joint_commands_msg()
        if msg_file is not None:
            typestore.register(get_types_from_msg(msg_file.read_text(), JOINT_COMMANDS_TYPE))
    return typestore


# ---------------------------------------------------------------------------- raw reading


def _ros1_type_name(msgtype: str) -> str:
    """'sensor_msgs/msg/JointState' -> 'sensor_msgs/JointState' (as rosbag info shows)."""
    return msgtype.replace('/msg/', '/')


#: One entry of a rosbag IDXDATA record: time (sec, nsec) and the offset in its chunk.
_INDEX_ENTRY = np.dtype([('sec', '<u4'), ('nsec', '<u4'), ('offset', '<u4')])


def _bulk_index_reader_class() -> type:
    """rosbags' rosbag1 Reader, but keeping each chunk's index as one numpy block.

    rosbags builds one Python tuple per message while opening a bag, which is a third of
    the time for a 60 s run (200,000 messages); here an IDXDATA record is one
    `np.frombuffer`. The rest of Reader (connections, chunk infos, chunk access) is
    reused; `Reader.messages` is not used on this reader (see `_read_raw`).
    """
    from rosbags.rosbag1.reader import Header, Reader, ReaderError, RecordType, read_uint32

    class BulkIndexReader(Reader):  # type: ignore[misc]
        def read_index_data(self, pos: int, indexes: dict[int, list[Any]]) -> None:
            header = Header.read(self.bio, RecordType.IDXDATA)
            if (version := header.get_uint32('ver')) != 1:
                msg = f'IDXDATA version {version} is not supported.'
                raise ReaderError(msg)
            count = header.get_uint32('count')
            size = read_uint32(self.bio)
            if size != count * _INDEX_ENTRY.itemsize:
                msg = f'IDXDATA of chunk {pos} has {size} bytes for {count} entries.'
                raise ReaderError(msg)
            entries = np.frombuffer(self.bio.read(size), dtype=_INDEX_ENTRY, count=count)
            first_ns = int(entries[0]['sec']) * _NS_PER_S + int(entries[0]['nsec']) if count else 0
            # (first time, chunk) sorts blocks like rosbags sorts its entries.
            indexes[header.get_uint32('conn')].append((first_ns, pos, entries))

    return BulkIndexReader


def _index(reader: Any, connections: Sequence[Any]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(bag times (ns), chunk positions, offsets in chunk) of `connections`, time-ordered."""
    blocks = [block for connection in connections for block in reader.indexes[connection.id]]
    if not blocks:
        empty = np.empty(0, dtype=np.int64)
        return empty, empty, empty
    entries = np.concatenate([block[2] for block in blocks])
    times_ns = entries['sec'].astype(np.int64) * _NS_PER_S + entries['nsec']
    chunk_pos = np.repeat([block[1] for block in blocks], [len(block[2]) for block in blocks])
    order = np.argsort(times_ns, kind='stable')
    return times_ns[order], chunk_pos[order], entries['offset'].astype(np.int64)[order]


def _read_raw(reader: Any, connections: Sequence[Any]) -> tuple[np.ndarray, list[bytes]]:
    """Return (bag times (ns), raw message bytes) of `connections`, in time order.

    Slices the records straight out of each chunk via the index, which is several times
    faster than `Reader.messages` for 60,000 messages.
    """
    times_ns, chunk_positions, offsets = _index(reader, connections)
    raws: list[bytes] = []
    append = raws.append
    unpack_u32 = _U32.unpack_from
    chunk_pos = -1
    chunk = b''
    for entry_chunk, offset in zip(chunk_positions.tolist(), offsets.tolist()):
        if entry_chunk != chunk_pos:
            chunk_pos = entry_chunk
            info = reader.chunks[chunk_pos]
            reader.bio.seek(info.datapos)
            chunk = info.decompressor(reader.bio.read(info.datasize))
        while True:
            (header_len,) = unpack_u32(chunk, offset)
            header_end = offset + 4 + header_len
            (data_len,) = unpack_u32(chunk, header_end)
            op_at = chunk.find(b'\x04\x00\x00\x00op=', offset + 4, header_end)
            if op_at < 0:
                msg = f'A record in chunk {chunk_pos} has no op field.'
                raise BagAnalysisError(msg)
            if chunk[op_at + 7] == 2:  # MSGDATA; a CONNECTION record (7) may come first
                break
            offset = header_end + 4 + data_len
        append(chunk[header_end + 4:header_end + 4 + data_len])
    return times_ns, raws


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


def _stamps_ns(rows: np.ndarray) -> np.ndarray:
    """Header stamps (ns) of uniform rows whose message starts with std_msgs/Header."""
    secs_nsecs = _column(rows, 4, '<u4', 2).astype(np.int64)
    return secs_nsecs[:, 0] * _NS_PER_S + secs_nsecs[:, 1]


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
    if cursor.pos != rows.shape[1] or any(
            not np.array_equal(rows[:, start - 4:start], np.broadcast_to(rows[0, start - 4:start],
                                                                        (len(rows), 4)))
            for start in starts):
        return None
    if not (rows[:, 12:fixed_end] == rows[0, 12:fixed_end]).all():
        return None
    count = len(names)
    arrays = [_column(rows, start, '<f8', count) for start in starts]
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
    if not (rows[:, 12:floats_at] == rows[0, 12:floats_at]).all():
        return None
    return _stamps_ns(rows), _column(rows, floats_at, '<f8', _ODOM_FLOATS)


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


def _column_union(name_lists: Sequence[Sequence[str]]) -> list[str]:
    """Joint names seen, tutorial order first, unknown names after in order of appearance."""
    seen = {name for names in name_lists for name in names}
    extra = []
    for names in name_lists:
        extra.extend(name for name in names if name not in JOINT_INDEX and name not in extra)
    return [name for name in JOINT_NAMES if name in seen] + extra


def _read_joint_states(reader: Any, connections: Sequence[Any], typestore: Any,
                       start_ns: int, warnings: list[str]) -> JointStateSeries:
    bag_ns, raws = _read_raw(reader, connections)
    standard = all(connection.digest == JOINT_STATE_MD5 for connection in connections)
    fast = _joint_states_fast(raws) if standard else None
    if fast is not None:
        stamps_ns, names, (position, velocity, effort) = fast
        names = [bare_joint_name(name) for name in names]
        if not names:  # a nameless JointState lists joints in tutorial order
            names = list(JOINT_NAMES[:position.shape[1]])
    else:
        parsed = []
        for raw in raws:
            if standard:
                stamp_ns, msg_names, arrays = parse_names_arrays(raw, 3)
            else:
                msg = typestore.deserialize_ros1(raw, 'sensor_msgs/msg/JointState')
                stamp_ns = msg.header.stamp.sec * _NS_PER_S + msg.header.stamp.nanosec
                msg_names, arrays = msg.name, [msg.position, msg.velocity, msg.effort]
            parsed.append((stamp_ns, [bare_joint_name(name) for name in msg_names]
                           or list(JOINT_NAMES[:len(arrays[0])]), arrays))
        names = _column_union([msg_names for _, msg_names, _ in parsed])
        column = {name: index for index, name in enumerate(names)}
        stamps_ns = np.array([stamp for stamp, _, _ in parsed], dtype=np.int64)
        position, velocity, effort = (np.full((len(parsed), len(names)), np.nan) for _ in range(3))
        for row, (_, msg_names, arrays) in enumerate(parsed):
            for target, values in zip((position, velocity, effort), arrays):
                count = min(len(values), len(msg_names))
                target[row, [column[name] for name in msg_names[:count]]] = values[:count]
    stamped = stamps_ns > 0
    if stamped.any():
        offset_s = float(np.median(np.abs(stamps_ns[stamped] - bag_ns[stamped]))) / _NS_PER_S
        if offset_s > _CLOCK_MISMATCH_S:
            warnings.append(f'{JOINT_STATES_TOPIC} header stamps are {offset_s:.3g} s from their '
                            'bag record times (was /use_sim_time false while recording?); '
                            'times relative to bag start may be off.')
    t_s = (_series_times(stamps_ns, bag_ns) - start_ns) / _NS_PER_S
    return JointStateSeries(t_s, tuple(names), position, velocity, effort)


def _read_commands(reader: Any, connections: Sequence[Any], typestore: Any, start_ns: int,
                   warnings: list[str]) -> JointCommandSeries:
    bag_ns, raws = _read_raw(reader, connections)
    fast = all(connection.digest == JOINT_COMMANDS_MD5 for connection in connections)
    if not fast and JOINT_COMMANDS_TYPE not in typestore.fielddefs:
        msg = ('The bag has no definition of osrf_msgs/JointCommands and '
               f'{_JOINT_COMMANDS_MSG_RELPATH} was not found; cannot read {JOINT_COMMANDS_TOPIC}.')
        raise BagAnalysisError(msg)
    position = np.full((len(raws), NUM_JOINTS), np.nan)
    stamps_ns = np.empty(len(raws), dtype=np.int64)
    unknown: set[str] = set()
    for row, raw in enumerate(raws):
        if fast:
            stamp_ns, names, (values,) = parse_names_arrays(raw, 1)
        else:
            msg = typestore.deserialize_ros1(raw, JOINT_COMMANDS_TYPE)
            stamp_ns = msg.header.stamp.sec * _NS_PER_S + msg.header.stamp.nanosec
            names, values = msg.name, msg.position
        stamps_ns[row] = stamp_ns
        names = [bare_joint_name(name) for name in names] or JOINT_NAMES
        for name, value in zip(names, values):
            index = JOINT_INDEX.get(name)
            if index is None:
                unknown.add(name)
            else:
                position[row, index] = value
    if unknown:
        warnings.append(f'{JOINT_COMMANDS_TOPIC} names unknown joints, ignored: '
                        f'{", ".join(sorted(unknown))}.')
    t_ns = _stamps_or_bag_times(stamps_ns, bag_ns)
    order = np.argsort(t_ns, kind='stable')
    position = position[order]
    t_s = (t_ns[order] - start_ns) / _NS_PER_S
    # Zero-order hold per joint: index of the latest row that commanded it.
    latest = np.where(np.isnan(position), -1, np.arange(len(position))[:, None])
    latest = np.maximum.accumulate(latest, axis=0) if len(position) else latest
    held = np.where(latest >= 0, position[np.maximum(latest, 0), np.arange(NUM_JOINTS)], np.nan)
    return JointCommandSeries(t_s, position, held)


def _read_pelvis(reader: Any, connections: Sequence[Any], typestore: Any,
                 start_ns: int) -> PelvisSeries:
    bag_ns, raws = _read_raw(reader, connections)
    fast = None
    if all(connection.digest == ODOMETRY_MD5 for connection in connections):
        fast = _odometry_fast(raws)
    if fast is not None:
        stamps_ns, floats = fast
    else:
        stamps_ns = np.empty(len(raws), dtype=np.int64)
        floats = np.empty((len(raws), _ODOM_FLOATS))
        for row, raw in enumerate(raws):
            msg = typestore.deserialize_ros1(raw, 'nav_msgs/msg/Odometry')
            stamps_ns[row] = msg.header.stamp.sec * _NS_PER_S + msg.header.stamp.nanosec
            pose, twist = msg.pose.pose, msg.twist.twist
            floats[row, 0:7] = [pose.position.x, pose.position.y, pose.position.z,
                                pose.orientation.x, pose.orientation.y, pose.orientation.z,
                                pose.orientation.w]
            floats[row, 43:49] = [twist.linear.x, twist.linear.y, twist.linear.z,
                                  twist.angular.x, twist.angular.y, twist.angular.z]
    t_s = (_series_times(stamps_ns, bag_ns) - start_ns) / _NS_PER_S
    return PelvisSeries(t_s, floats[:, 0:3].copy(), floats[:, 3:7].copy(),
                        floats[:, 43:46].copy(), floats[:, 46:49].copy())


def _read_modes(reader: Any, connections: Sequence[Any], typestore: Any,
                start_ns: int) -> list[tuple[float, str]]:
    bag_ns, raws = _read_raw(reader, connections)
    modes: list[tuple[float, str]] = []
    for time_ns, raw in zip(bag_ns, raws):
        mode = typestore.deserialize_ros1(raw, 'std_msgs/msg/String').data
        if not modes or modes[-1][1] != mode:
            modes.append(((int(time_ns) - start_ns) / _NS_PER_S, mode))
    return modes


def _open_reader(path: Path) -> Any:
    """Open `path` with rosbags, turning every failure into a BagAnalysisError."""
    from rosbags.rosbag1 import ReaderError

    if not path.exists():
        active = path.with_name(path.name + '.active')
        hint = (f'; {active} exists, so the recording was interrupted: run '
                f'`rosbag reindex {active}` and analyze that file' if active.exists() else '')
        msg = f'{path}: no such file{hint}.'
        raise BagAnalysisError(msg)
    if path.is_dir():
        msg = f'{path} is a directory; expected a ROS 1 .bag file (ROS 2 bags are not supported).'
        raise BagAnalysisError(msg)
    try:
        with path.open('rb') as stream:
            magic = stream.read(len(_BAG_MAGIC))
    except OSError as err:
        msg = f'Could not open {path}: {err.strerror or err}.'
        raise BagAnalysisError(msg) from err
    if not magic.startswith(_BAG_MAGIC[:9]):  # '#ROSBAG V', any version
        msg = f'{path} is not a ROS 1 bag (it does not start with "#ROSBAG V2.0").'
        raise BagAnalysisError(msg)
    reader = _bulk_index_reader_class()(path)
    try:
        reader.open()
    except ReaderError as err:
        text = str(err)
        if 'not indexed' in text or path.name.endswith('.active'):
            msg = (f'{path} is not indexed (an interrupted `rosbag record` leaves an unindexed '
                   f'.bag.active file); run `rosbag reindex {path}` and analyze it again.')
        elif 'magic' in text or 'empty' in text:
            msg = f'{path} is not a ROS 1 bag (it does not start with "#ROSBAG V2.0").'
        else:
            msg = f'Could not read {path}: {text}'
        raise BagAnalysisError(msg) from err
    except (OSError, struct.error, ValueError, KeyError, IndexError, AssertionError) as err:
        hint = (f'; if it is an interrupted recording, run `rosbag reindex {path}`'
                if path.name.endswith('.active') else '')
        msg = f'Could not read {path}, it looks damaged ({type(err).__name__}: {err}){hint}.'
        raise BagAnalysisError(msg) from err
    return reader


def read_bag(path: Path | str) -> BagData:
    """Read the topics the analysis needs from a ROS 1 bag.

    Args:
        path: The .bag file.

    Returns:
        The extracted series; a series is None when its topic is not in the bag.

    Raises:
        BagAnalysisError: Missing file, not a bag, unindexed or damaged bag.
    """
    path = Path(path)
    reader = _open_reader(path)
    try:
        return _read_open_bag(path, reader)
    except (struct.error, ValueError, KeyError, IndexError, UnicodeDecodeError) as err:
        msg = f'Could not read {path}, a message is damaged ({type(err).__name__}: {err}).'
        raise BagAnalysisError(msg) from err
    finally:
        reader.close()


def _read_open_bag(path: Path, reader: Any) -> BagData:
    by_topic: dict[str, list[Any]] = {}
    for connection in reader.connections:
        by_topic.setdefault(connection.topic, []).append(connection)
    topics: dict[str, TopicSummary] = {}
    start_ns, end_ns = None, None
    for topic in sorted(by_topic):
        connections = by_topic[topic]
        times_ns = _index(reader, connections)[0]
        rate_hz = None
        if len(times_ns):
            first_ns, last_ns = int(times_ns[0]), int(times_ns[-1])
            start_ns = first_ns if start_ns is None else min(start_ns, first_ns)
            end_ns = last_ns if end_ns is None else max(end_ns, last_ns)
            if last_ns > first_ns:
                rate_hz = (len(times_ns) - 1) / ((last_ns - first_ns) / _NS_PER_S)
        msgtypes = sorted({_ros1_type_name(c.msgtype) for c in connections})
        topics[topic] = TopicSummary(' | '.join(msgtypes), len(times_ns), rate_hz)
    start_ns = start_ns or 0
    end_ns = end_ns or start_ns

    typestore = load_typestore(reader.connections)
    warnings: list[str] = []
    states = commands = pelvis = None
    modes: list[tuple[float, str]] = []
    if by_topic.get(JOINT_STATES_TOPIC):
        states = _read_joint_states(reader, by_topic[JOINT_STATES_TOPIC], typestore, start_ns,
                                    warnings)
    if by_topic.get(JOINT_COMMANDS_TOPIC):
        commands = _read_commands(reader, by_topic[JOINT_COMMANDS_TOPIC], typestore, start_ns,
                                  warnings)
    if by_topic.get(ODOM_TOPIC):
        pelvis = _read_pelvis(reader, by_topic[ODOM_TOPIC], typestore, start_ns)
    if by_topic.get(CONTROL_MODE_TOPIC):
        modes = _read_modes(reader, by_topic[CONTROL_MODE_TOPIC], typestore, start_ns)
    return BagData(path, start_ns / _NS_PER_S, (end_ns - start_ns) / _NS_PER_S, topics, states,
                   commands, pelvis, modes, warnings)


# ---------------------------------------------------------------------------- metrics


@dataclass(frozen=True)
class JointTracking:
    """Tracking of one joint: RMS and max |command - measured| (rad) over `samples`."""

    rms_error_rad: float | None
    max_error_rad: float | None
    samples: int
    commanded: bool
    measured_range_rad: float | None


@dataclass(frozen=True)
class EffortSaturation:
    """Time a joint spent at its effort limit (s of sim time) and when it first did."""

    limit_nm: float
    duration_s: float
    first_time_s: float
    samples: int


@dataclass(frozen=True)
class Analysis:
    """The metrics of one run. Times are seconds from bag start; None = not available."""

    data: BagData
    fell: bool | None
    fall_time_s: float | None
    min_pelvis_height_m: float | None
    joints: dict[str, JointTracking]
    command_rate_hz: float | None
    command_age_mean_s: float | None
    command_age_max_s: float | None
    effort_saturation: dict[str, EffortSaturation] | None
    unavailable: dict[str, str]

    @property
    def mode_timeline(self) -> list[tuple[float, str]]:
        return self.data.modes

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (see analyze_bag --help for the keys and units)."""
        data = self.data
        return {
            'bag': str(data.path),
            'start_time': data.start_time_s,
            'duration': data.duration_s,
            'topics': {name: {'type': topic.msgtype, 'count': topic.count,
                              'rate': topic.rate_hz} for name, topic in data.topics.items()},
            'mode_timeline': [{'time': t_s, 'mode': mode} for t_s, mode in data.modes],
            'fell': self.fell,
            'fall_time': self.fall_time_s,
            'min_pelvis_height': self.min_pelvis_height_m,
            'joints': {name: {'rms_error': joint.rms_error_rad, 'max_error': joint.max_error_rad,
                              'samples': joint.samples, 'commanded': joint.commanded,
                              'measured_range': joint.measured_range_rad}
                       for name, joint in self.joints.items()},
            'command_rate': self.command_rate_hz,
            'command_count': 0 if data.commands is None else len(data.commands.t_s),
            'command_age': (None if self.command_age_mean_s is None else
                            {'mean': self.command_age_mean_s, 'max': self.command_age_max_s}),
            'effort_saturation': (None if self.effort_saturation is None else {
                name: {'limit': sat.limit_nm, 'duration': sat.duration_s,
                       'first_time': sat.first_time_s, 'samples': sat.samples}
                for name, sat in self.effort_saturation.items()}),
            'thresholds': {'fall_height': FALL_HEIGHT_M, 'moved_range': MOVED_RANGE_RAD,
                           'command_change': COMMAND_CHANGE_RAD,
                           'effort_tolerance': EFFORT_LIMIT_TOLERANCE_NM},
            'unavailable': dict(self.unavailable),
            'warnings': list(data.warnings),
        }


def _sample_durations_s(t_s: np.ndarray) -> np.ndarray:
    """How long each sample stands for: the gap to the next one (median gap for the last)."""
    if len(t_s) < 2:
        return np.zeros(len(t_s))
    gaps = np.diff(t_s)
    return np.append(gaps, np.median(gaps))


def _effort_saturation(states: JointStateSeries) -> dict[str, EffortSaturation]:
    durations_s = _sample_durations_s(states.t_s)
    result = {}
    for column, name in enumerate(states.names):
        limit = EFFORT_LIMITS_NM.get(name)
        if limit is None:
            continue
        with np.errstate(invalid='ignore'):
            hit = np.abs(states.effort[:, column]) >= limit - EFFORT_LIMIT_TOLERANCE_NM
        if hit.any():
            result[name] = EffortSaturation(limit, float(durations_s[hit].sum()),
                                            float(states.t_s[np.argmax(hit)]), int(hit.sum()))
    return result


def _nan_range(values: np.ndarray) -> float | None:
    finite = values[np.isfinite(values)]
    return float(finite.max() - finite.min()) if len(finite) else None


def analyze(data: BagData) -> Analysis:
    """Compute fall, tracking, command timing and effort saturation from `data`."""
    unavailable: dict[str, str] = {}
    fell = fall_time_s = min_height_m = None
    if data.pelvis is None or not len(data.pelvis.t_s):
        unavailable['fall'] = f'no {ODOM_TOPIC} in the bag'
    else:
        height_m = data.pelvis.position_m[:, 2]
        below = height_m < FALL_HEIGHT_M
        fell = bool(below.any())
        fall_time_s = float(data.pelvis.t_s[np.argmax(below)]) if fell else None
        min_height_m = float(height_m.min())

    commands = data.commands
    command_rate_hz = None
    if commands is None or not len(commands.t_s):
        unavailable['commands'] = f'no {JOINT_COMMANDS_TOPIC} in the bag'
    elif len(commands.t_s) > 1 and commands.t_s[-1] > commands.t_s[0]:
        command_rate_hz = (len(commands.t_s) - 1) / float(commands.t_s[-1] - commands.t_s[0])

    states = data.joint_states
    joints: dict[str, JointTracking] = {}
    age_mean_s = age_max_s = None
    saturation = None
    if states is None or not len(states.t_s):
        reason = f'no {JOINT_STATES_TOPIC} in the bag'
        unavailable.update(joints=reason, command_age=reason, effort_saturation=reason)
    else:
        saturation = _effort_saturation(states)
        latest = np.full(len(states.t_s), -1)
        if commands is not None and len(commands.t_s):
            latest = np.searchsorted(commands.t_s, states.t_s, side='right') - 1
            with_command = latest >= 0
            if with_command.any():
                ages_s = states.t_s[with_command] - commands.t_s[latest[with_command]]
                age_mean_s, age_max_s = float(ages_s.mean()), float(ages_s.max())
        for column, name in enumerate(states.names):
            measured = states.position[:, column]
            measured_range = _nan_range(measured)
            moved = measured_range is not None and measured_range > MOVED_RANGE_RAD
            index = JOINT_INDEX.get(name)
            commanded = False
            rms = max_error = None
            samples = 0
            if index is not None and commands is not None and len(commands.t_s):
                sent = commands.position[:, index]
                sent = sent[np.isfinite(sent)]
                commanded = bool(len(sent))
                changed = commanded and np.any(np.abs(sent - sent[0]) > COMMAND_CHANGE_RAD)
                moved = moved or bool(changed)
                rows = latest >= 0
                target = commands.held[latest[rows], index]
                errors = target - measured[rows]
                errors = errors[np.isfinite(errors)]
                samples = len(errors)
                if samples:
                    rms = float(np.sqrt(np.mean(errors ** 2)))
                    max_error = float(np.abs(errors).max())
            if moved:
                joints[name] = JointTracking(rms, max_error, samples, commanded, measured_range)
        if commands is None or not len(commands.t_s):
            unavailable['command_age'] = f'no {JOINT_COMMANDS_TOPIC} in the bag'
    return Analysis(data, fell, fall_time_s, min_height_m, joints, command_rate_hz,
                    age_mean_s, age_max_s, saturation, unavailable)


def analyze_bag(path: Path | str) -> Analysis:
    """:func:`read_bag` then :func:`analyze`."""
    return analyze(read_bag(path))
