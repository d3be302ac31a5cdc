"""The head's Hokuyo laser as Gazebo's ray sensor saw the world, by MuJoCo's ray queries.

multisense_sl.urdf's sensor: 720 rays over +-90 degrees in the x-y plane of
head_hokuyo_frame, 0.10-30 m, Gaussian noise of 0.01 m, 40 Hz. One `mj_multiRay` call casts
the 720 rays from the frame's origin, placed by the `head` body's pose, hokuyo_joint's origin
and the spindle's angle (frames.py), against the world's geoms and the robot's own, as
Gazebo's laser saw the robot, except the head's, which the frame sits on. Only collision
geoms count (group 0: the robot's and the world's solids; visuals are group 1, the VRC mud's
volume group 3), as Gazebo's ray sensor hit collision shapes.

A heightfield (the VRC course's terrain) is not left to `mj_multiRay`, whose heightfield test
took 480 ms a scan on the course (0.2 ms in the flat world) and starved the course's real
time whenever a recorder listened: the rays are cast on a copy of the model without its
heightfields, and each heightfield is met by heightfield_march.py's march over its heights.

What a ray reports follows REP 117 (sensor_msgs/LaserScan's convention): its true distance
plus noise; +inf when nothing is within range_max (no return; Gazebo 1.9 reported range_max
there, which a consumer cannot tell from a wall at 30 m), -inf when the hit is closer than
range_min. The noise of a scan is drawn from a generator seeded by (seed, the scan's stamp),
so a scan is the same whoever listened before it: live, offline and replayed runs agree.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import mujoco
import numpy as np

from tutorial_atlas_control.sensors.frames import (
    HEAD_HOKUYO_FRAME,
    HEAD_LINK,
    frame_in_head,
)
from tutorial_atlas_control.sensors.heightfield_march import Heightfield

__all__ = ['COLLISION_GROUPS', 'HOKUYO', 'HokuyoLaser', 'LaserSpec']

#: The geom groups rays see: the collision geoms.
COLLISION_GROUPS = np.array([1, 0, 0, 0, 0, 0], dtype=np.uint8)
#: A group no ray sees: the heightfields' in the rays' copy of the model.
_UNSEEN_GROUP = 5


@dataclass(frozen=True)
class LaserSpec:
    """A planar laser's figures (the URDF's <ray> block): samples over [min, max] (rad),
    ranges (m), the noise's standard deviation (m) and the update rate (Hz)."""

    samples: int = 720
    min_angle: float = -1.570796
    max_angle: float = 1.570796
    range_min: float = 0.10
    range_max: float = 30.0
    noise_m: float = 0.01
    rate_hz: float = 40.0

    @property
    def angle_increment(self) -> float:
        """Gazebo's: the span over samples - 1 (both ends are rays)."""
        return (self.max_angle - self.min_angle) / (self.samples - 1)

    def angles(self) -> np.ndarray:
        return self.min_angle + self.angle_increment * np.arange(self.samples)


#: multisense_sl.urdf's head_hokuyo_sensor.
HOKUYO = LaserSpec()


class HokuyoLaser:
    """The laser on a model with a `head` body: scans of the MjData given (its poses as last
    computed by mj_forward/mj_step).

    Args:
        seed: the noise's seed (the run's ~sensor_seed).
    """

    def __init__(self, model: mujoco.MjModel, spec: LaserSpec = HOKUYO, seed: int = 0) -> None:
        self.model = model
        self.spec = spec
        self.seed = seed
        self.head_body = int(model.body(HEAD_LINK).id)
        angles = spec.angles()
        #: The rays' unit directions in head_hokuyo_frame.
        self.local_rays = np.stack((np.cos(angles), np.sin(angles), np.zeros_like(angles)), 1)
        self._world_rays = np.zeros((spec.samples, 3))
        self.geom_id = np.zeros(spec.samples, dtype=np.int32)
        self.distance = np.zeros(spec.samples)
        self.origin = np.zeros(3)
        hfields = [geom for geom in range(model.ngeom)
                   if model.geom_type[geom] == mujoco.mjtGeom.mjGEOM_HFIELD
                   and COLLISION_GROUPS[min(int(model.geom_group[geom]), 5)]]
        #: The heightfields, marched here; the model the rays are cast on without them.
        self.heightfields = [Heightfield(model, geom) for geom in hfields]
        self._ray_model = model
        if hfields:
            self._ray_model = copy.copy(model)
            for geom in hfields:
                self._ray_model.geom_group[geom] = _UNSEEN_GROUP

    def frame_pose(self, data: mujoco.MjData, spindle_rad: float
                   ) -> tuple[np.ndarray, np.ndarray]:
        """head_hokuyo_frame's position (m) and rotation (frame to world) in the world."""
        offset, rotation = frame_in_head(HEAD_HOKUYO_FRAME, spindle_rad)
        head_rotation = data.xmat[self.head_body].reshape(3, 3)
        return data.xpos[self.head_body] + head_rotation @ offset, head_rotation @ rotation

    def cast(self, data: mujoco.MjData, spindle_rad: float) -> np.ndarray:
        """The rays' true distances (m; -1 where nothing is hit within range_max): a view,
        valid until the next call; `geom_id` holds the geoms hit."""
        origin, rotation = self.frame_pose(data, spindle_rad)
        self.origin[:] = origin
        np.matmul(self.local_rays, rotation.T, out=self._world_rays)
        mujoco.mj_multiRay(self._ray_model, data, self.origin, self._world_rays.reshape(-1),
                           COLLISION_GROUPS, 1, self.head_body, self.geom_id, self.distance,
                           None, self.spec.samples, self.spec.range_max)
        for heightfield in self.heightfields:
            ground = heightfield.distances(self.origin, self._world_rays, self.spec.range_max)
            nearer = (ground >= 0.0) & ((self.distance < 0.0) | (ground < self.distance))
            self.distance[nearer] = ground[nearer]
            self.geom_id[nearer] = heightfield.geom
        return self.distance

    def ranges(self, distance: np.ndarray, stamp_ns: int, out: np.ndarray) -> None:
        """A scan's ranges into `out` (float32): `distance` (cast's) with the noise of the
        scan stamped `stamp_ns`, +inf without a return, -inf closer than range_min."""
        spec = self.spec
        noise = np.random.default_rng((self.seed, stamp_ns)).normal(0.0, spec.noise_m,
                                                                    spec.samples)
        hit = distance >= 0.0
        ranges = np.where(hit, distance + noise, np.inf)
        ranges[hit & (distance < spec.range_min)] = -np.inf
        ranges[hit & (distance > spec.range_max)] = np.inf
        out[:] = ranges

    def scan(self, data: mujoco.MjData, spindle_rad: float, stamp_ns: int,
             out: np.ndarray) -> None:
        """The scan of `data` with the spindle at `spindle_rad`, stamped `stamp_ns`."""
        self.ranges(self.cast(data, spindle_rad), stamp_ns, out)
