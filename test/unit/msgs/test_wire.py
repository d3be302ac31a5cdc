"""wire.py's pre-serialized messages are byte-identical to genpy's serialization."""

import io

import genpy
import numpy as np
import pytest
from atlas_msgs.msg import AtlasState, ForceTorqueSensors
from geometry_msgs.msg import TransformStamped, WrenchStamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from rospy.msg import serialize_message
from sensor_msgs.msg import Imu, JointState
from tf2_msgs.msg import TFMessage

from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.msgs import wire

STAMP_NS = 12 * wire.NS_PER_S + 345_678


def genpy_bytes(msg, seq=1):
    buffer = io.BytesIO()
    serialize_message(buffer, seq, msg)
    return buffer.getvalue()


def test_clock():
    assert wire.clock_bytes(STAMP_NS) == genpy_bytes(Clock(clock=genpy.Time(12, 345_678)))


def test_joint_state():
    rng = np.random.default_rng(1)
    values = rng.normal(size=(3, len(JOINT_NAMES)))
    msg = wire.JointStateWire(JOINT_NAMES)
    msg.position[:], msg.velocity[:], msg.effort[:] = values
    expected = JointState(name=list(JOINT_NAMES), position=list(values[0]),
                          velocity=list(values[1]), effort=list(values[2]))
    expected.header.stamp = genpy.Time(12, 345_678)
    assert msg.to_bytes(STAMP_NS) == genpy_bytes(expected, seq=1)
    assert msg.to_bytes(STAMP_NS) == genpy_bytes(expected, seq=2)  # seq counts up


def test_imu():
    msg = wire.ImuWire('pelvis')
    msg.orientation_xyzw[:] = (0.1, 0.2, 0.3, 0.9)
    msg.angular_velocity[:] = (1.0, 2.0, 3.0)
    msg.linear_acceleration[:] = (4.0, 5.0, 9.81)
    expected = Imu()
    expected.header.frame_id = 'pelvis'
    expected.header.stamp = genpy.Time(12, 345_678)
    o = expected.orientation
    o.x, o.y, o.z, o.w = 0.1, 0.2, 0.3, 0.9
    a, acc = expected.angular_velocity, expected.linear_acceleration
    a.x, a.y, a.z = 1.0, 2.0, 3.0
    acc.x, acc.y, acc.z = 4.0, 5.0, 9.81
    assert msg.to_bytes(STAMP_NS) == genpy_bytes(expected)


def test_wrench_stamped():
    msg = wire.WrenchStampedWire('l_foot')
    msg.force[:], msg.torque[:] = (1.0, 2.0, 450.0), (0.1, -0.2, 0.3)
    expected = WrenchStamped()
    expected.header.frame_id = 'l_foot'
    expected.header.stamp = genpy.Time(12, 345_678)
    f, t = expected.wrench.force, expected.wrench.torque
    f.x, f.y, f.z = 1.0, 2.0, 450.0
    t.x, t.y, t.z = 0.1, -0.2, 0.3
    assert msg.to_bytes(STAMP_NS) == genpy_bytes(expected)


def test_odometry():
    msg = wire.OdometryWire('world', 'pelvis')
    msg.position[:], msg.orientation_xyzw[:] = (0.1, 0.2, 0.93), (0.0, 0.0, 0.0, 1.0)
    msg.linear[:], msg.angular[:] = (0.5, 0.0, -0.1), (0.0, 0.2, 0.0)
    expected = Odometry()
    expected.header.frame_id, expected.child_frame_id = 'world', 'pelvis'
    expected.header.stamp = genpy.Time(12, 345_678)
    p, o = expected.pose.pose.position, expected.pose.pose.orientation
    p.x, p.y, p.z = 0.1, 0.2, 0.93
    o.x, o.y, o.z, o.w = 0.0, 0.0, 0.0, 1.0
    lin, ang = expected.twist.twist.linear, expected.twist.twist.angular
    lin.x, lin.y, lin.z = 0.5, 0.0, -0.1
    ang.x, ang.y, ang.z = 0.0, 0.2, 0.0
    assert msg.to_bytes(STAMP_NS) == genpy_bytes(expected)


@pytest.mark.parametrize('stamp_ns', [0, 1, wire.NS_PER_S - 1, 2**32 * wire.NS_PER_S - 1])
def test_stamp_split(stamp_ns):
    raw = wire.clock_bytes(stamp_ns)
    secs, nsecs = divmod(stamp_ns, wire.NS_PER_S)
    assert raw == genpy_bytes(Clock(clock=genpy.Time(secs, nsecs)))


def test_controller_statistics():
    from atlas_msgs.msg import ControllerStatistics

    msg = wire.ControllerStatisticsWire()
    msg.set_values(0.001, 0.0105, 33.28e-6, 1.0)
    expected = ControllerStatistics(command_age=0.001, command_age_mean=0.0105,
                                    command_age_variance=33.28e-6, command_age_window_size=1.0)
    expected.header.stamp = genpy.Time(12, 345_678)
    assert msg.to_bytes(STAMP_NS) == genpy_bytes(expected)


def test_transform():
    msg = wire.TransformWire('world', 'pelvis')
    msg.translation[:] = (0.1, -0.2, 0.92)
    msg.rotation_xyzw[:] = (0.0, 0.1, 0.0, 0.995)
    expected = TransformStamped()
    expected.header.frame_id = 'world'
    expected.header.stamp = genpy.Time(12, 345_678)
    expected.header.seq = 1
    expected.child_frame_id = 'pelvis'
    t, r = expected.transform.translation, expected.transform.rotation
    t.x, t.y, t.z = 0.1, -0.2, 0.92
    r.x, r.y, r.z, r.w = 0.0, 0.1, 0.0, 0.995
    # TFMessage has no header of its own: the transform's seq is set by the writer.
    assert msg.to_bytes(STAMP_NS) == genpy_bytes(TFMessage(transforms=[expected]))
    expected.header.seq = 2
    assert msg.to_bytes(STAMP_NS) == genpy_bytes(TFMessage(transforms=[expected]))


def _wrench(target, values) -> None:
    f, t = target.force, target.torque
    f.x, f.y, f.z, t.x, t.y, t.z = (float(v) for v in values)


def test_atlas_state():
    """Every field in place: float32 joint arrays (rounded as genpy rounds), k_effort as
    bytes, IMU and the four wrenches as float64."""
    rng = np.random.default_rng(2)
    joints = rng.normal(size=(9, len(JOINT_NAMES))) * 100
    k_effort = rng.integers(0, 256, size=len(JOINT_NAMES), dtype=np.uint8)
    tail = rng.normal(size=34)
    msg = wire.AtlasStateWire(len(JOINT_NAMES))
    msg.joints[:] = joints  # float64 in, float32 stored
    msg.k_effort[:] = k_effort
    msg.floats[:] = tail
    expected = AtlasState()
    expected.header.stamp = genpy.Time(12, 345_678)
    for field, row in zip(wire.AtlasStateWire.FIELDS, joints):
        setattr(expected, field, [float(v) for v in row])
    expected.k_effort = k_effort.tobytes()
    o = expected.orientation
    o.x, o.y, o.z, o.w = tail[0:4]
    v, a = expected.angular_velocity, expected.linear_acceleration
    v.x, v.y, v.z = tail[4:7]
    a.x, a.y, a.z = tail[7:10]
    for k, name in enumerate(wire.FORCE_TORQUE_SENSORS):
        _wrench(getattr(expected, name), tail[10 + 6 * k:16 + 6 * k])
    assert msg.to_bytes(STAMP_NS) == genpy_bytes(expected)
    assert np.array_equal(msg.arrays['kd_position'], joints[5].astype(np.float32))
    assert np.array_equal(msg.wrenches['l_hand'], tail[22:28])


def test_force_torque_sensors():
    msg = wire.ForceTorqueSensorsWire()
    values = np.arange(24, dtype=float) - 430.0
    for k, name in enumerate(wire.FORCE_TORQUE_SENSORS):
        msg.wrenches[name][:] = values[6 * k:6 * k + 6]
    expected = ForceTorqueSensors()
    expected.header.stamp = genpy.Time(12, 345_678)
    for k, name in enumerate(wire.FORCE_TORQUE_SENSORS):
        _wrench(getattr(expected, name), values[6 * k:6 * k + 6])
    assert msg.to_bytes(STAMP_NS) == genpy_bytes(expected)


def test_atlas_state_joint_indices_are_the_tutorial_order():
    """AtlasState's constants index its arrays; the port fills them in JOINT_NAMES order."""
    assert [getattr(AtlasState, name) for name in JOINT_NAMES] == list(range(len(JOINT_NAMES)))
