"""Pre-serialized ROS 1 messages for the simulator's 1 kHz topics. No rospy.

rospy's generic path costs the simulator most of each step: Publisher.publish() runs
genpy's serializer into a BytesIO, then hands the bytes to one QueuedConnection per
subscriber, whose write_data() ends in time.sleep(0) to yield the GIL to that
connection's writer thread: 5 topics x 1 recorder = 5 thread handoffs per step.

Here each message is a bytearray laid out once (TCPROS length prefix, std_msgs/Header,
constant strings) whose float fields are numpy views, so a step only copies numbers in
and stamps the header. The node sends these bytes itself (node/transport.py); offline runs
write them, without the TCPROS length prefix, to a bag. The layouts are checked against
genpy in test/unit/msgs/test_wire.py.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence

import numpy as np

from tutorial_atlas_control.units import NS_PER_S

_PREFIX_HEADER = struct.Struct('<IIII')  # TCPROS length, Header.seq, stamp.secs, stamp.nsecs
_CLOCK = struct.Struct('<III')


def _string(text: str) -> bytes:
    raw = text.encode()
    return struct.pack('<I', len(raw)) + raw


class StampedWire:
    """A message that starts with std_msgs/Header, then `middle` bytes, then float64s.

    `floats` is a writable float64 view of the trailing block.
    """

    def __init__(self, frame_id: str, floats: int, middle: bytes = b'') -> None:
        body = _string(frame_id) + middle
        self.buf = bytearray(16 + len(body) + 8 * floats)
        self.buf[16:16 + len(body)] = body
        self.floats = np.frombuffer(self.buf, dtype='<f8', offset=16 + len(body), count=floats)
        self.seq = 0

    def stamped(self, stamp_ns: int) -> bytearray:
        """The next message, stamped `stamp_ns`: the buffer itself, valid until the next
        call (the node's batch copies it; a copy of 1 kB costs less than a new bytes object)."""
        self.seq += 1
        secs, nsecs = divmod(stamp_ns, NS_PER_S)
        _PREFIX_HEADER.pack_into(self.buf, 0, len(self.buf) - 4, self.seq, secs, nsecs)
        return self.buf

    def to_bytes(self, stamp_ns: int) -> bytes:
        return bytes(self.stamped(stamp_ns))


class JointStateWire(StampedWire):
    """sensor_msgs/JointState with fixed names; position/velocity/effort are views."""

    def __init__(self, names: Sequence[str]) -> None:
        count = len(names)
        names_block = struct.pack('<I', count) + b''.join(_string(name) for name in names)
        array = struct.pack('<I', count) + bytes(8 * count)
        super().__init__('', 0, names_block + array * 3)
        start = len(self.buf) - 3 * len(array)
        self.position, self.velocity, self.effort = (
            np.frombuffer(self.buf, dtype='<f8', offset=start + k * len(array) + 4, count=count)
            for k in range(3))


class PositionsWire(StampedWire):
    """sensor_msgs/JointState without names, velocities or efforts: `positions` (a view)
    carries `count` numbers. The trailing float's eight zero bytes are the empty velocity
    and effort arrays' lengths."""

    def __init__(self, count: int) -> None:
        super().__init__('', count + 1, struct.pack('<II', 0, count))
        self.positions = self.floats[:count]


class ImuWire(StampedWire):
    """sensor_msgs/Imu, covariances 0: orientation (x y z w), angular_velocity,
    linear_acceleration are views."""

    def __init__(self, frame_id: str) -> None:
        super().__init__(frame_id, 4 + 9 + 3 + 9 + 3 + 9)
        self.orientation_xyzw = self.floats[0:4]
        self.angular_velocity = self.floats[13:16]
        self.linear_acceleration = self.floats[25:28]


class WrenchStampedWire(StampedWire):
    """geometry_msgs/WrenchStamped: force and torque are views."""

    def __init__(self, frame_id: str) -> None:
        super().__init__(frame_id, 6)
        self.force = self.floats[0:3]
        self.torque = self.floats[3:6]


#: A geometry_msgs/Wrench's six float64s: force (x y z), then torque (x y z).
WRENCH_FLOATS = 6
#: AtlasState's and ForceTorqueSensors' wrenches, in their order in both messages.
FORCE_TORQUE_SENSORS = ('l_foot', 'r_foot', 'l_hand', 'r_hand')


class AtlasStateWire(StampedWire):
    """atlas_msgs/AtlasState for a fixed number of joints.

    Its nine float32 joint arrays are the rows of `joints` (a (9, N) strided view that
    skips each array's length prefix; `arrays[field]` is one row), `k_effort` a uint8
    view; the float64 tail holds orientation (x y z w), angular_velocity,
    linear_acceleration and the four wrenches (`wrenches[name]`: force, then torque).
    """

    FIELDS = ('position', 'velocity', 'effort', 'kp_position', 'ki_position', 'kd_position',
              'kp_velocity', 'i_effort_min', 'i_effort_max')

    def __init__(self, joint_count: int) -> None:
        count = struct.pack('<I', joint_count)
        array = count + bytes(4 * joint_count)
        super().__init__('', 4 + 3 + 3 + WRENCH_FLOATS * len(FORCE_TORQUE_SENSORS),
                         array * len(self.FIELDS) + count + bytes(joint_count))
        first = 16 + 4  # the first array's length: after TCPROS length, seq, stamp, frame_id ''
        self.joints = np.ndarray((len(self.FIELDS), joint_count), dtype='<f4', buffer=self.buf,
                                 offset=first + 4, strides=(len(array), 4))
        self.arrays = dict(zip(self.FIELDS, self.joints))
        k_effort_at = first + len(self.FIELDS) * len(array) + 4
        self.k_effort = np.frombuffer(self.buf, dtype=np.uint8, offset=k_effort_at,
                                      count=joint_count)
        self.orientation_xyzw = self.floats[0:4]
        self.angular_velocity = self.floats[4:7]
        self.linear_acceleration = self.floats[7:10]
        self.wrench_floats = self.floats[10:]
        self.wrenches = {name: self.wrench_floats[k * WRENCH_FLOATS:(k + 1) * WRENCH_FLOATS]
                         for k, name in enumerate(FORCE_TORQUE_SENSORS)}


class ForceTorqueSensorsWire(StampedWire):
    """atlas_msgs/ForceTorqueSensors: `wrenches[name]` (force, then torque) are views of
    `floats`, in FORCE_TORQUE_SENSORS order."""

    def __init__(self) -> None:
        super().__init__('', WRENCH_FLOATS * len(FORCE_TORQUE_SENSORS))
        self.wrenches = {name: self.floats[k * WRENCH_FLOATS:(k + 1) * WRENCH_FLOATS]
                         for k, name in enumerate(FORCE_TORQUE_SENSORS)}


class LaserScanWire(StampedWire):
    """sensor_msgs/LaserScan with a fixed number of rays: its seven float32 figures
    (angle_min, angle_max, angle_increment, time_increment, scan_time, range_min,
    range_max) set once, `ranges` a float32 view; `intensities` empty."""

    def __init__(self, frame_id: str, figures: Sequence[float], samples: int) -> None:
        middle = struct.pack('<7f', *figures) + struct.pack('<I', samples) + bytes(4 * samples)
        super().__init__(frame_id, 0, middle + struct.pack('<I', 0))
        self.ranges = np.frombuffer(self.buf, dtype='<f4', offset=len(self.buf) - 4 - 4 * samples,
                                    count=samples)


class OdometryWire(StampedWire):
    """nav_msgs/Odometry, covariances 0: position, orientation (x y z w), linear, angular."""

    def __init__(self, frame_id: str, child_frame_id: str) -> None:
        super().__init__(frame_id, 7 + 36 + 6 + 36, _string(child_frame_id))
        self.position = self.floats[0:3]
        self.orientation_xyzw = self.floats[3:7]
        self.linear = self.floats[43:46]
        self.angular = self.floats[46:49]


class ControllerStatisticsWire(StampedWire):
    """atlas_msgs/ControllerStatistics: command_age, command_age_mean, command_age_variance
    and command_age_window_size, set together by set_values."""

    _VALUES = struct.Struct('<4d')

    def __init__(self) -> None:
        super().__init__('', 4)
        self._values_at = len(self.buf) - self._VALUES.size

    def set_values(self, age_s: float, mean_s: float, variance_s2: float,
                   window_s: float) -> None:
        """The four values at once (one struct pack, cheaper than four numpy assignments)."""
        self._VALUES.pack_into(self.buf, self._values_at, age_s, mean_s, variance_s2, window_s)


class JointCommandsWire(StampedWire):
    """osrf_msgs/JointCommands with fixed names; each of its nine arrays is a view in `arrays`.

    For writers of many commands to the same joints (offline runs write traj_yaml's 50 Hz).
    """

    FIELDS = ('position', 'velocity', 'effort', 'kp_position', 'ki_position', 'kd_position',
              'kp_velocity', 'i_effort_min', 'i_effort_max')

    def __init__(self, names: Sequence[str]) -> None:
        count = len(names)
        names_block = struct.pack('<I', count) + b''.join(_string(name) for name in names)
        array = struct.pack('<I', count) + bytes(8 * count)
        super().__init__('', 0, names_block + array * len(self.FIELDS))
        start = len(self.buf) - len(self.FIELDS) * len(array)
        self.arrays = {
            field: np.frombuffer(self.buf, dtype='<f8', offset=start + k * len(array) + 4,
                                 count=count)
            for k, field in enumerate(self.FIELDS)}


class TransformWire:
    """tf2_msgs/TFMessage holding one geometry_msgs/TransformStamped (parent -> child);
    translation and rotation (x y z w) are views.

    TFMessage starts with the array length, not a Header, so it has its own layout.
    """

    def __init__(self, frame_id: str, child_frame_id: str) -> None:
        names = _string(frame_id) + _string(child_frame_id)
        self.buf = bytearray(8 + 12 + len(names) + 8 * 7)
        struct.pack_into('<I', self.buf, 4, 1)  # one transform
        self.buf[20:20 + len(names)] = names
        floats = np.frombuffer(self.buf, dtype='<f8', offset=20 + len(names), count=7)
        self.translation = floats[0:3]
        self.rotation_xyzw = floats[3:7]
        self.rotation_xyzw[3] = 1.0
        self.seq = 0

    def to_bytes(self, stamp_ns: int) -> bytes:
        self.seq += 1
        secs, nsecs = divmod(stamp_ns, NS_PER_S)
        struct.pack_into('<I', self.buf, 0, len(self.buf) - 4)
        struct.pack_into('<III', self.buf, 8, self.seq, secs, nsecs)
        return bytes(self.buf)


class TransformsWire:
    """tf2_msgs/TFMessage holding one geometry_msgs/TransformStamped per (parent, child) of
    `frames`, all stamped alike (robot_state_publisher's moving joints); `translations`
    (N, 3) and `rotations_xyzw` (N, 4) are views of a staging block.

    The transforms' numbers sit between names of varying length, so they are not one
    strided view of the message: stamped() scatters the staging block (stamp and seven
    float64s per transform) into the message with one precomputed byte index. The headers'
    seq stays 0, as roscpp leaves it in a TFMessage.
    """

    _STAGE = np.dtype([('secs', '<u4'), ('nsecs', '<u4'), ('floats', '<f8', (7,))])

    def __init__(self, frames: Sequence[tuple[str, str]]) -> None:
        parts = [struct.pack('<II', 0, len(frames))]  # TCPROS length (set below), count
        starts = []  # byte offset of each transform's stamp, then of its floats
        at = 8
        for parent, child in frames:
            names = _string(parent) + _string(child)
            starts.append((at + 4, at + 12 + len(names)))
            parts.append(bytes(12) + names + bytes(56))
            at += 12 + len(names) + 56
        self.buf = bytearray(b''.join(parts))
        struct.pack_into('<I', self.buf, 0, len(self.buf) - 4)
        self._bytes = np.frombuffer(self.buf, dtype=np.uint8)
        self._stage = np.zeros(len(frames), dtype=self._STAGE)
        self._index = np.array([np.r_[stamp:stamp + 8, floats:floats + 56]
                                for stamp, floats in starts], dtype=np.intp).reshape(-1)
        self._stage_bytes = self._stage.view(np.uint8).reshape(-1)
        self.translations = self._stage['floats'][:, 0:3]
        self.rotations_xyzw = self._stage['floats'][:, 3:7]
        self.rotations_xyzw[:, 3] = 1.0

    def stamped(self, stamp_ns: int) -> bytearray:
        """The message with every transform stamped `stamp_ns`: the buffer itself, valid
        until the next call."""
        secs, nsecs = divmod(stamp_ns, NS_PER_S)
        self._stage['secs'] = secs
        self._stage['nsecs'] = nsecs
        self._bytes[self._index] = self._stage_bytes
        return self.buf

    def to_bytes(self, stamp_ns: int) -> bytes:
        return bytes(self.stamped(stamp_ns))


def clock_bytes(stamp_ns: int) -> bytes:
    """rosgraph_msgs/Clock with its TCPROS length prefix."""
    secs, nsecs = divmod(stamp_ns, NS_PER_S)
    return _CLOCK.pack(8, secs, nsecs)
