"""The links' transforms robot_state_publisher would publish, computed in the simulator.

Debian's robot_state_publisher 1.15 looks its tf_prefix parameter up on the master at
every publication (searchParam, hasParam, getParam): at real_time_factor 0 that is the
master's busiest client. The simulator has the joint angles already, so it publishes the
same transforms itself. What is reproduced, from robot_state_publisher 1.15:

- one transform per moving URDF joint (revolute, continuous, prismatic), parent link ->
  child link, equal to `origin * motion(position)`: a rotation about the joint's axis
  (revolute) or a translation along it (prismatic), after the joint's fixed origin;
- in one TFMessage, ordered by joint name (it iterates a std::map), each stamped with the
  joint_states message's stamp;
- published when a joint_states stamp reaches the last published stamp plus
  1 / publish_frequency (RspSchedule), the first time at 1 / publish_frequency;
- fixed joints once, latched, on /tf_static (floating and planar joints: nowhere).

No ROS here; the wire layout is msgs/wire.py's TransformsWire.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tutorial_atlas_control.sim.urdf import UrdfJoint
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['LinkTransforms', 'RspSchedule', 'StaticTransform', 'quaternion_multiply',
           'rpy_quaternion']

#: URDF joint types robot_state_publisher publishes on /tf, by how they move.
ROTATING = ('revolute', 'continuous')
SLIDING = ('prismatic',)
#: ... and once on /tf_static.
FIXED = ('fixed',)


def quaternion_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a * b for quaternions (x y z w) in the last axis (broadcast over the others)."""
    ax, ay, az, aw = np.moveaxis(a, -1, 0)
    bx, by, bz, bw = np.moveaxis(b, -1, 0)
    return np.stack((aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw,
                     aw * bw - ax * bx - ay * by - az * bz), axis=-1)


def rpy_quaternion(rpy_rad: np.ndarray) -> np.ndarray:
    """A URDF origin's rpy (fixed axes: roll about x, then pitch about y, then yaw about z)
    as a quaternion (x y z w)."""
    half = 0.5 * np.asarray(rpy_rad, dtype=float)
    (cr, cp, cy), (sr, sp, sy) = np.cos(half), np.sin(half)
    return np.array([sr * cp * cy - cr * sp * sy,
                     cr * sp * cy + sr * cp * sy,
                     cr * cp * sy - sr * sp * cy,
                     cr * cp * cy + sr * sp * sy])


def rotate(quaternion_xyzw: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """`vector` rotated by a unit quaternion (x y z w)."""
    u, w = quaternion_xyzw[:3], quaternion_xyzw[3]
    t = 2.0 * np.cross(u, vector)
    return vector + w * t + np.cross(u, t)


@dataclass(frozen=True)
class StaticTransform:
    """A fixed joint's transform (/tf_static): parent -> child, translation, rotation."""

    parent: str
    child: str
    translation_m: np.ndarray
    rotation_xyzw: np.ndarray


class LinkTransforms:
    """The moving joints' transforms from joint positions (vectorised over the joints).

    Args:
        joints: the URDF's joints (urdf.read_joints).
        position_names: the names, in order, of the positions given to `compute` (the
            joint_states message's); a moving URDF joint not among them is not published,
            as robot_state_publisher publishes only the joints a message carries.
    """

    def __init__(self, joints: Sequence[UrdfJoint], position_names: Sequence[str]) -> None:
        index = {name: k for k, name in enumerate(position_names)}
        moving = sorted((j for j in joints if j.kind in ROTATING + SLIDING and j.name in index),
                        key=lambda j: j.name.encode())  # std::map<std::string> order: bytes
        #: (parent link, child link) of each published transform, in message order.
        self.frames: tuple[tuple[str, str], ...] = tuple((j.parent, j.child) for j in moving)
        self.joint_names: tuple[str, ...] = tuple(j.name for j in moving)
        self.position_index = np.array([index[j.name] for j in moving], dtype=np.intp)
        axes = np.array([j.axis / np.linalg.norm(j.axis) for j in moving]).reshape(-1, 3)
        self._origin_xyz = np.array([j.origin_m for j in moving], dtype=float).reshape(-1, 3)
        self._origin_quat = np.array([rpy_quaternion(j.rpy_rad) for j in moving]).reshape(-1, 4)
        self._rotating = np.array([j.kind in ROTATING for j in moving], dtype=bool)
        self._axes = axes
        # A prismatic joint slides along its axis as seen in the parent (origin-rotated).
        self._slide_axes = np.array([rotate(q, a) for q, a in zip(self._origin_quat, axes)])
        self._slide_axes[self._rotating] = 0.0
        # origin * (axis sin(q/2), cos(q/2)) = sin(q/2) origin * (axis, 0) + cos(q/2) origin:
        # two constant quaternions per joint, so a publication costs two products and a sum.
        rot_axes = np.c_[axes * self._rotating[:, None], np.zeros(len(moving))]
        self._sin_part = quaternion_multiply(self._origin_quat, rot_axes).reshape(-1, 4)
        self._has_sliding = not bool(np.all(self._rotating))
        #: Fixed joints, published once on /tf_static (in joint name order).
        self.static: tuple[StaticTransform, ...] = tuple(
            StaticTransform(j.parent, j.child, np.array(j.origin_m, dtype=float),
                            rpy_quaternion(j.rpy_rad))
            for j in sorted((j for j in joints if j.kind in FIXED), key=lambda j: j.name.encode()))

    def __len__(self) -> int:
        return len(self.frames)

    def compute(self, positions: np.ndarray, translations: np.ndarray,
                rotations_xyzw: np.ndarray) -> None:
        """Write each moving joint's transform for `positions` (rad or m, in position_names
        order) into `translations` (N, 3) and `rotations_xyzw` (N, 4) (views of a wire)."""
        q = positions[self.position_index]
        half = (0.5 * q * self._rotating)[:, None]
        np.multiply(self._sin_part, np.sin(half), out=rotations_xyzw)
        rotations_xyzw += self._origin_quat * np.cos(half)
        if self._has_sliding:
            translations[:] = self._origin_xyz + self._slide_axes * q[:, None]
        else:
            translations[:] = self._origin_xyz


class RspSchedule:
    """When robot_state_publisher 1.15 publishes, given the joint_states stamps it receives.

    It publishes a message whose stamp is at least the last published stamp plus the
    interval (0 before the first, so the first at one interval); when ROS time goes back
    (a reset of sim time) it forgets the last one.
    """

    def __init__(self, publish_frequency_hz: float) -> None:
        # ros::Duration(1.0 / max(f, 1.0)): rounded to whole nanoseconds.
        self.interval_ns = round(NS_PER_S / max(publish_frequency_hz, 1.0))
        self.last_ns = 0
        self._previous_ns = 0

    def due(self, stamp_ns: int) -> bool:
        """Whether a joint_states message stamped `stamp_ns` is published (and note it)."""
        if stamp_ns < self._previous_ns:
            self.last_ns = 0
        self._previous_ns = stamp_ns
        if stamp_ns >= self.last_ns + self.interval_ns:
            self.last_ns = stamp_ns
            return True
        return False
