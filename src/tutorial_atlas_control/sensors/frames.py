"""The MultiSense SL head's frames, as multisense_sl.urdf (DRCSim 2.7) fixes them on `head`.

Plain numbers, one place for every user of the head's sensors: the laser (its spindle,
`hokuyo_joint`, turns `hokuyo_link` about the head's x axis; the scan is taken in
`head_hokuyo_frame`), the stereo cameras and `head_imu_link`. The MuJoCo model's `head`
body is the URDF's `head` link (same origin and axes), so a frame's pose in the world is the
head body's pose times the chain below. No ROS, no MuJoCo.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ['CAMERA_FRAMES', 'HEAD_FRAMES', 'HEAD_HOKUYO_FRAME', 'HEAD_IMU_FRAME', 'HEAD_LINK',
           'HEAD_IMU', 'HOKUYO_AXIS', 'HOKUYO_FRAME', 'HOKUYO_JOINT', 'HOKUYO_LINK', 'FixedFrame',
           'frame_in_head', 'rpy_matrix', 'spindle_matrix']

HEAD_LINK = 'head'
HOKUYO_LINK = 'hokuyo_link'
HEAD_HOKUYO_FRAME = 'head_hokuyo_frame'
HEAD_IMU_FRAME = 'head_imu_link'
#: The spindle's axis in `head` (and in `hokuyo_link`): x, the head's forward axis.
HOKUYO_AXIS = (1.0, 0.0, 0.0)


def rpy_matrix(rpy_rad: tuple[float, float, float]) -> np.ndarray:
    """A URDF origin's rpy (roll about x, pitch about y, yaw about z, fixed axes) as a
    rotation matrix: Rz(yaw) Ry(pitch) Rx(roll)."""
    (cr, cp, cy), (sr, sp, sy) = (np.cos(rpy_rad), np.sin(rpy_rad))
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def spindle_matrix(angle_rad: float) -> np.ndarray:
    """hokuyo_joint's rotation at `angle_rad` about HOKUYO_AXIS (x)."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


@dataclass(frozen=True)
class FixedFrame:
    """A URDF joint's origin: `child`'s pose in `parent` (m, rad), the joint's name."""

    joint: str
    parent: str
    child: str
    xyz_m: tuple[float, float, float]
    rpy_rad: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def rotation(self) -> np.ndarray:
        return rpy_matrix(self.rpy_rad)


#: hokuyo_joint's origin (continuous, about HOKUYO_AXIS): hokuyo_link at spindle angle 0.
HOKUYO_JOINT = FixedFrame('hokuyo_joint', HEAD_LINK, HOKUYO_LINK, (-0.0446, 0.0, 0.0880))
#: The laser's frame on the spindle (head_hokuyo_joint, fixed).
HOKUYO_FRAME = FixedFrame('head_hokuyo_joint', HOKUYO_LINK, HEAD_HOKUYO_FRAME,
                          (0.03, 0.0, 0.015))
#: The stereo pair on `head` and their optical frames (z forward, x right, y down).
_OPTICAL_RPY = (-1.5708, 0.0, -1.5708)
CAMERA_FRAMES: tuple[FixedFrame, ...] = (
    FixedFrame('left_camera_frame_joint', HEAD_LINK, 'left_camera_frame', (0.0, 0.035, -0.002)),
    FixedFrame('left_camera_optical_frame_joint', 'left_camera_frame',
               'left_camera_optical_frame', (0.0, 0.0, 0.0), _OPTICAL_RPY),
    FixedFrame('right_camera_frame_joint', HEAD_LINK, 'right_camera_frame',
               (0.0, -0.035, -0.002)),
    FixedFrame('right_camera_optical_frame_joint', 'right_camera_frame',
               'right_camera_optical_frame', (0.0, 0.0, 0.0), _OPTICAL_RPY),
)
#: The head's IMU (head_imu_joint, fixed), at the stereo pair's height.
HEAD_IMU = FixedFrame('head_imu_joint', HEAD_LINK, HEAD_IMU_FRAME, (-0.0475, 0.035, 0.0))
#: Every fixed frame below `head` (the URDF's fixed joints, for /tf_static).
HEAD_FRAMES: tuple[FixedFrame, ...] = (HOKUYO_FRAME, *CAMERA_FRAMES, HEAD_IMU)
_BY_CHILD = {frame.child: frame for frame in (HOKUYO_JOINT, *HEAD_FRAMES)}


def frame_in_head(child: str, spindle_rad: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """`child`'s position (m) and rotation (3x3, child to head) in `head`, the spindle at
    `spindle_rad` for the frames it carries.

    Raises:
        KeyError: not one of the head's frames.
    """
    chain = []
    name = child
    while name != HEAD_LINK:
        frame = _BY_CHILD[name]
        chain.append(frame)
        name = frame.parent
    position, rotation = np.zeros(3), np.eye(3)
    for frame in reversed(chain):
        position = position + rotation @ np.array(frame.xyz_m)
        rotation = rotation @ frame.rotation()
        if frame is HOKUYO_JOINT:
            rotation = rotation @ spindle_matrix(spindle_rad)
    return position, rotation
