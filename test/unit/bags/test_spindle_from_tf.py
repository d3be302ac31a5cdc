"""The spindle's angle at each recorded scan comes from the bag's /tf (head -> hokuyo_link,
the simulator's, stamped with the sim time it holds), not from set_spindle_speed's record
times, which are the recorder's receipts: a live bag's spindle simulated from them lagged
its /tf by 94 mrad throughout."""

from __future__ import annotations

import math
import struct

import numpy as np

from tutorial_atlas_control.bags import LaserScans, hokuyo_angles, spindle_angles

SPEED_RAD_S = 8.0  # past 2 pi (a quaternion's half turn) within the run: unwrapped


def _transform(stamp_ns: int, parent: str, child: str, angle_rad: float) -> bytes:
    """A geometry_msgs/TransformStamped as ROS 1 writes it (the rotation about x)."""
    names = b''.join(struct.pack('<I', len(name)) + name.encode() for name in (parent, child))
    return (struct.pack('<3I', 7, stamp_ns // 1_000_000_000, stamp_ns % 1_000_000_000)
            + names + struct.pack('<7d', 0.0, 0.0, 0.03, math.sin(angle_rad / 2), 0.0, 0.0,
                                  math.cos(angle_rad / 2)))


def _tf(*transforms: bytes) -> bytes:
    """A tf2_msgs/TFMessage's bytes."""
    return struct.pack('<I', len(transforms)) + b''.join(transforms)


def _recorded_tf() -> list[bytes]:
    """50 Hz from 20 ms to 1 s: the spindle's transform among others, and the pelvis's alone;
    the last sample sent twice (a second publisher)."""
    raws = []
    for stamp in range(20_000_000, 1_000_000_001, 20_000_000):
        angle = SPEED_RAD_S * stamp / 1e9
        raws.append(_tf(_transform(stamp, 'pelvis', 'ltorso', 0.3),
                        _transform(stamp, 'head', 'hokuyo_link', angle)))
        raws.append(_tf(_transform(stamp, 'world', 'pelvis', 0.1)))
    return raws + raws[-2:-1]


def test_the_spindle_s_angles_are_read_from_tf_in_order_and_unwrapped() -> None:
    stamps, angles = hokuyo_angles(_recorded_tf())
    assert list(stamps) == list(range(20_000_000, 1_000_000_001, 20_000_000))
    np.testing.assert_allclose(angles, SPEED_RAD_S * stamps / 1e9, rtol=0.0, atol=1e-12)
    assert hokuyo_angles([_tf(_transform(0, 'world', 'pelvis', 0.1))]) is None


def test_the_scans_take_the_tf_s_angle_not_the_commands_record_times() -> None:
    """Scans every 25 ms from 5 ms to 1.03 s (before the first sample and after the last
    too); a command recorded 94 ms after the spindle began to turn, as a live bag had it."""
    stamp_ns = np.arange(5_000_000, 1_030_000_001, 25_000_000, dtype=np.int64)
    scans = LaserScans(stamp_ns, np.ones((len(stamp_ns), 3), np.float32), 'head_hokuyo_frame',
                       -1.0, 1.0, [(94_000_000, SPEED_RAD_S)], hokuyo_angles(_recorded_tf()))
    np.testing.assert_allclose(spindle_angles(scans), SPEED_RAD_S * stamp_ns / 1e9,
                               rtol=0.0, atol=1e-9)
    from_commands = spindle_angles(LaserScans(*[getattr(scans, f) for f in (
        'stamp_ns', 'ranges', 'frame_id', 'angle_min', 'angle_increment',
        'spindle_commands')]))
    assert np.max(np.abs(from_commands[-10:] - SPEED_RAD_S * stamp_ns[-10:] / 1e9)) > 0.4
