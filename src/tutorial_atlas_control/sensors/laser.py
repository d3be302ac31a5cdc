"""The head's Hokuyo laser as Gazebo's ray sensor saw the world, by MuJoCo's ray queries.

multisense_sl.urdf's sensor: 720 rays over +-90 degrees in the x-y plane of
head_hokuyo_frame, 0.10-30 m, Gaussian noise of 0.01 m, 40 Hz. One `mj_multiRay` call casts
the 720 rays from the frame's origin, placed by the `head` body's pose, hokuyo_joint's origin
and the spindle's angle (frames.py), against the world's geoms and the robot's own, as
Gazebo's laser saw the robot, except the head's, which the frame sits on. Only collision
geoms count (group 0: the robot's and the world's solids; visuals are group 1, the VRC mud's
volume group 3), as Gazebo's ray sensor hit collision shapes.

A heightfield (the VRC course's terrain) is not left to `mj_multiRay`: MuJoCo's ray test of
a heightfield visits every cell of the rectangle the ray spans seen from above, and 720 rays
of 30 m over the course's 513 x 513 terrain took 480 ms a scan (0.2 ms in the flat world),
which starved the course's real time whenever a recorder listened. The rays are cast on a
copy of the model without its heightfields, and each heightfield is met by marching the rays
in MARCH_STEP_M steps over its heights, bilinear between its vertices (MuJoCo's triangles lie
within millimetres of that), the crossing then bisected to BISECT_TOL_M.

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

__all__ = ['COLLISION_GROUPS', 'HOKUYO', 'HokuyoLaser', 'LaserSpec']

#: The geom groups rays see: the collision geoms.
COLLISION_GROUPS = np.array([1, 0, 0, 0, 0, 0], dtype=np.uint8)
#: A heightfield is marched in steps of this length (m; the course's cells are 0.195 m),
#: and its crossing bisected to this (m).
MARCH_STEP_M = 0.2
BISECT_TOL_M = 1e-4
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


class Heightfield:
    """One heightfield geom (unturned) as heights over a grid: where rays first meet it."""

    def __init__(self, model: mujoco.MjModel, geom: int) -> None:
        if not np.allclose(model.geom_quat[geom], (1.0, 0.0, 0.0, 0.0)):
            raise ValueError(f'heightfield geom {geom} is turned: the laser takes it upright')
        field = int(model.geom_dataid[geom])
        rows, cols = int(model.hfield_nrow[field]), int(model.hfield_ncol[field])
        start = int(model.hfield_adr[field])
        self.geom = geom
        self.half_x, self.half_y, top, _ = (float(v) for v in model.hfield_size[field])
        self.centre = np.array(model.geom_pos[geom], dtype=float)
        #: Heights (m, world z) of the vertices, row 0 at -y, column 0 at -x.
        self.heights = (self.centre[2] + top * np.asarray(
            model.hfield_data[start:start + rows * cols]).reshape(rows, cols))
        self.lowest, self.highest = float(self.heights.min()), float(self.heights.max())

    def height_m(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """The surface's height under world points (bilinear); -inf outside it."""
        rows, cols = self.heights.shape
        col = (x - self.centre[0] + self.half_x) / (2.0 * self.half_x) * (cols - 1)
        row = (y - self.centre[1] + self.half_y) / (2.0 * self.half_y) * (rows - 1)
        inside = (col >= 0.0) & (col <= cols - 1) & (row >= 0.0) & (row <= rows - 1)
        col, row = np.clip(col, 0.0, cols - 1.0), np.clip(row, 0.0, rows - 1.0)
        c0 = np.minimum(col.astype(int), cols - 2)
        r0 = np.minimum(row.astype(int), rows - 2)
        fc, fr = col - c0, row - r0
        h = self.heights
        surface = ((h[r0, c0] * (1.0 - fc) + h[r0, c0 + 1] * fc) * (1.0 - fr)
                   + (h[r0 + 1, c0] * (1.0 - fc) + h[r0 + 1, c0 + 1] * fc) * fr)
        return np.where(inside, surface, -np.inf)

    def distances(self, origin: np.ndarray, rays: np.ndarray, range_m: float) -> np.ndarray:
        """Each ray's distance (m) to where it first goes below the surface, within
        `range_m`; -1 where it does not (0 for every ray from under the surface)."""
        result = np.full(len(rays), -1.0)
        if self.height_m(origin[:1], origin[1:2])[0] >= origin[2]:
            return np.zeros(len(rays))
        # How far a ray can meet the surface: not past its lowest point going down, never
        # going up or level from above its highest.
        reach = np.full(len(rays), float(range_m))
        falling = rays[:, 2] < 0.0
        reach[falling] = np.minimum(reach[falling],
                                    (origin[2] - self.lowest) / -rays[falling, 2])
        if origin[2] > self.highest:
            reach[~falling] = 0.0
        live = np.flatnonzero(reach > 0.0)
        if not len(live):
            return result
        steps = np.arange(MARCH_STEP_M, float(reach[live].max()) + MARCH_STEP_M, MARCH_STEP_M)
        points = origin + steps[:, None, None] * rays[live]  # (steps, rays, 3)
        below = ((points[..., 2] <= self.height_m(points[..., 0], points[..., 1]))
                 & (steps[:, None] <= reach[live] + MARCH_STEP_M))
        met = below.any(axis=0)
        first = np.argmax(below, axis=0)[met]
        near = np.where(first > 0, steps[np.maximum(first - 1, 0)], 0.0)
        far = steps[first]
        rays_met = rays[live[met]]
        while far.size and float((far - near).max()) > BISECT_TOL_M:
            middle = 0.5 * (near + far)
            at = origin + middle[:, None] * rays_met
            under = at[:, 2] <= self.height_m(at[:, 0], at[:, 1])
            far = np.where(under, middle, far)
            near = np.where(under, near, middle)
        distance = 0.5 * (near + far)
        within = distance <= range_m
        result[live[met][within]] = distance[within]
        return result
