"""Atlas at a start: the pelvis at the start's (x, y), turned by its yaw, at the height that
stands the soles on the ground under them.

The ground is the loaded world's (sim.ground): the VRC course's is not at z = 0, and the z
of a DRCSim start was Gazebo's spawn height (a hint, ignored here). With every joint at 0
(reset_to_initial's pose) the pelvis is raised or lowered until the lowest sole corner
touches the ground under it, as the flat world's SPAWN_HEIGHT_M does at the origin.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from tutorial_atlas_control.course import Start
from tutorial_atlas_control.sim.ground import Ground
from tutorial_atlas_control.sim.model import (
    ORIGIN_PELVIS_QPOS,
    SOLE_GEOMS,
    AtlasModel,
    ModelError,
    reset_to_initial,
)

__all__ = ['StartPose', 'home_qpos', 'sole_bottom_corners', 'start_line', 'start_pose',
           'yaw_quaternion']

#: A pelvis pose as the free joint's qpos: x y z, then the quaternion w x y z.
StartPose = np.ndarray
_CORNER_SIGNS = np.array([(sx, sy, -1.0) for sx in (-1.0, 1.0) for sy in (-1.0, 1.0)])


def yaw_quaternion(yaw_rad: float) -> np.ndarray:
    """The upright orientation turned by `yaw_rad` about z (w x y z)."""
    return np.array([math.cos(yaw_rad / 2.0), 0.0, 0.0, math.sin(yaw_rad / 2.0)])


def sole_bottom_corners(atlas: AtlasModel, data: mujoco.MjData) -> np.ndarray:
    """The bottom corners (8, 3) of both sole boxes in the world, as last computed."""
    model = atlas.model
    corners = []
    for name in SOLE_GEOMS:
        geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
        rotation = data.geom_xmat[geom].reshape(3, 3)
        corners.append(data.geom_xpos[geom] + (_CORNER_SIGNS * model.geom_size[geom]) @ rotation.T)
    return np.concatenate(corners)


def start_pose(atlas: AtlasModel, start: Start, ground: Ground | None = None) -> StartPose:
    """The pelvis's qpos (7,) at `start`, its soles on the ground under them (joints at 0).

    Raises:
        ModelError: no ground under a sole corner at the start (off the world's ground).
    """
    data = mujoco.MjData(atlas.model)
    pose = np.array([start.x_m, start.y_m, 0.0, *yaw_quaternion(start.yaw_rad)])
    reset_to_initial(atlas, data, pose)
    ground = ground if ground is not None else Ground(atlas.model, data)
    corners = sole_bottom_corners(atlas, data)
    heights = np.array([ground.height_m(x, y) for x, y in corners[:, :2].tolist()])
    if not np.all(np.isfinite(heights)):
        raise ModelError(f'{atlas.path.name} has no ground under the soles at the start '
                         f'x {start.x_m:g} m, y {start.y_m:g} m: give a start on its ground')
    pose[2] = float(np.max(heights - corners[:, 2]))
    return pose


def home_qpos(atlas: AtlasModel, start: Start | None, ground: Ground | None = None
              ) -> StartPose:
    """The pelvis's qpos (7,) a reset puts the robot at: start_pose's, or for None the
    model's spawn pose (upright at the origin, the soles on z = 0).

    Raises:
        ModelError: no ground under a sole corner at the start.
    """
    if start is None:
        return np.array(ORIGIN_PELVIS_QPOS)
    return start_pose(atlas, start, ground)


def start_line(start: Start, qpos: StartPose) -> str:
    """The simulator's line saying where `start` put the pelvis (`qpos`: start_pose's)."""
    name = f'{start.name} ' if start.name else ''
    x, y, z = (float(value) for value in qpos[:3])
    return (f'start {name}at x {x:.3f} m, y {y:.3f} m, yaw {math.degrees(start.yaw_rad):.1f} '
            f'deg: the pelvis at z {z:.3f} m puts the soles on the ground')
