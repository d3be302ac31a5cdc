"""A variant of the VRC Task 2 world (course/variants.py) compiled in memory for offline runs.

The qualification's MJCF (sim/vrc_task_2.xml) with the variant's changes made through
MuJoCo's model editing (MjSpec): the mud floor's friction, and each cinder block where the
variant puts it, its body and every start's keyframe alike (a run starts from a keyframe).
A moved block is raised as tools/make_vrc_world.py raises the world's: its lowest corner
BLOCK_CLEARANCE_M over the highest ground under its envelope, from which it settles. The
mud's damping is the simulator's own argument (AtlasSimulator's `mud_damping`). The model
keeps the qualification's file as its path: the mud's contact copy compiles from it (the
same geoms and bodies) and replay names it, so a variant's run is offline only.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from tutorial_atlas_control.bags import terrain_heights
from tutorial_atlas_control.course import (
    HEIGHTMAP,
    WORLD_MODEL_FILE,
    Block,
    CourseError,
    CourseVariant,
    block_corners,
)
from tutorial_atlas_control.resources import package_path
from tutorial_atlas_control.sim import AtlasModel, index_model

__all__ = ['BLOCK_CLEARANCE_M', 'MUD_FLOOR_GEOM', 'block_placement', 'highest_ground_m',
           'variant_model']

#: The mud pit's real floor in the course's MJCF.
MUD_FLOOR_GEOM = 'mud_ground_plane'
#: A placed block's lowest corner over the highest ground under it (m): the world's own.
BLOCK_CLEARANCE_M = 0.002


def _quaternion(block: Block) -> np.ndarray:
    """Gazebo's roll, pitch, yaw (fixed axes x, y, z) as a MuJoCo quaternion (w, x, y, z)."""
    quat = np.array([1.0, 0.0, 0.0, 0.0])
    for axis, angle in ((2, block.yaw_rad), (1, block.pitch_rad), (0, block.roll_rad)):
        turn = np.zeros(4)
        turn[0], turn[axis + 1] = math.cos(angle / 2), math.sin(angle / 2)
        mujoco.mju_mulQuat(quat, quat.copy(), turn)
    return quat


def highest_ground_m(heights: np.ndarray, x0: float, x1: float, y0: float, y1: float
                     ) -> float:
    """The highest terrain vertex (m) within one cell of the rectangle x0..x1, y0..y1
    (`heights`: bags.terrain_heights, rows from +y down, columns from -x)."""
    half, cell, last = HEIGHTMAP.size_m / 2, HEIGHTMAP.cell_m, heights.shape[0] - 1

    def index(v: float, low: bool) -> int:
        return int(np.clip(math.floor(v / cell) - 1 if low else math.ceil(v / cell) + 1,
                           0, last))

    c0, c1 = index(x0 + half, True), index(x1 + half, False)
    r0, r1 = index(half - y1, True), index(half - y0, False)
    return float(heights[r0:r1 + 1, c0:c1 + 1].max())


def block_placement(block: Block, heights: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The block's body position and quaternion: its pose, raised (never lowered) so that
    its envelope's lowest corner clears the highest ground under it by BLOCK_CLEARANCE_M."""
    corners = block_corners(block)
    ground = highest_ground_m(heights, corners[:, 0].min(), corners[:, 0].max(),
                              corners[:, 1].min(), corners[:, 1].max())
    lift = max(0.0, ground + BLOCK_CLEARANCE_M - float(corners[:, 2].min()))
    return np.array([block.x_m, block.y_m, block.z_m + lift]), _quaternion(block)


def variant_model(variant: CourseVariant) -> AtlasModel:
    """The course's world changed as `variant` says, compiled and indexed.

    Raises:
        CourseError: the package's course model is missing or lacks a block or the mud floor.
    """
    path = package_path('sim', WORLD_MODEL_FILE)
    if not path.is_file():
        raise CourseError(f'the course model {path} is missing from the package')
    spec = mujoco.MjSpec.from_file(str(path))
    floor = spec.geom(MUD_FLOOR_GEOM)
    if floor is None:
        raise CourseError(f'{path} has no geom {MUD_FLOOR_GEOM}')
    floor.friction[0] = variant.mud_floor_friction
    if variant.rubble_seed is not None:
        _place_blocks(spec, variant.blocks, path.name)
    return index_model(spec.compile(), path)


def _place_blocks(spec: mujoco.MjSpec, blocks: tuple[Block, ...], source: str) -> None:
    """Each block's body and its free joint's place in every keyframe moved to its pose."""
    addresses = spec.compile().jnt_qposadr
    heights = terrain_heights()
    for block in blocks:
        body, joint = spec.body(block.name), spec.joint(f'{block.name}_free')
        if body is None or joint is None:
            raise CourseError(f'{source} has no free block {block.name}')
        position, quat = block_placement(block, heights)
        body.pos, body.quat = position, quat
        start = int(addresses[joint.id])
        for key in spec.keys:
            qpos = np.array(key.qpos)
            qpos[start:start + 7] = np.concatenate([position, quat])
            key.qpos = qpos
