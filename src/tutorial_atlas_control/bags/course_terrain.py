"""The ground under a recorded run on DRCSim's VRC Task 2 course: whether the bag is such a
run, and the terrain's height under a world point.

A bag is a course run when the simulator's /atlas/sim_config names the course's model file
(as offline.world.recorded_world reads it back) or when the bag has /vrc_score. The terrain is
the package's sim/vrc_task_2_terrain.png with course.HEIGHTMAP's scaling, the image the
world's heightfield is made of.
"""

from __future__ import annotations

import functools

import numpy as np

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.reader import BagData
from tutorial_atlas_control.course import HEIGHTMAP, TERRAIN_FILE, WORLD_MODEL_FILE
from tutorial_atlas_control.resources import package_path
from tutorial_atlas_control.sim import SimConfig, SimConfigError

__all__ = ['above_ground', 'ground_under', 'is_course_run', 'terrain_heights']


def is_course_run(data: BagData) -> bool:
    """Whether `data`'s bag is a run on the VRC Task 2 course: a /atlas/sim_config naming the
    course's model file, or /vrc_score messages."""
    if getattr(data.topics.get(topics.VRC_SCORE), 'count', 0):
        return True
    for _t_s, text in data.sim_configs:
        try:
            config = SimConfig.from_json(text)
        except SimConfigError:
            continue
        if config.model_file == WORLD_MODEL_FILE:
            return True
    return False


@functools.cache
def terrain_heights() -> np.ndarray:
    """The course's terrain heights (m), rows from +y down, columns from -x (the image's
    layout), from the package's terrain image and course.HEIGHTMAP's scaling: read once a
    process (each try's fall, the plot, the landings and the map ask for it), read-only."""
    import matplotlib.image  # noqa: PLC0415 - only course runs need it

    grey = np.asarray(matplotlib.image.imread(package_path('sim', TERRAIN_FILE)))
    if grey.dtype.kind == 'f':  # matplotlib reads an 8-bit PNG as levels / 255
        grey = np.rint(grey * 255.0)
    heights = HEIGHTMAP.z0_m + HEIGHTMAP.relief_m * grey.astype(float) / HEIGHTMAP.brightest
    heights.setflags(write=False)
    return heights


def ground_under(heights: np.ndarray, x_m: np.ndarray, y_m: np.ndarray) -> np.ndarray:
    """The terrain's height (m) under world points, bilinear between the heightmap's
    vertices (MuJoCo's triangles differ by millimetres on the hills, not on ramps)."""
    half, cell = HEIGHTMAP.size_m / 2.0, HEIGHTMAP.cell_m
    last = heights.shape[0] - 1
    col = np.clip((np.asarray(x_m) + half) / cell, 0.0, last)
    row = np.clip((half - np.asarray(y_m)) / cell, 0.0, last)
    c0, r0 = np.minimum(col.astype(int), last - 1), np.minimum(row.astype(int), last - 1)
    fc, fr = col - c0, row - r0
    top = heights[r0, c0] * (1 - fc) + heights[r0, c0 + 1] * fc
    bottom = heights[r0 + 1, c0] * (1 - fc) + heights[r0 + 1, c0 + 1] * fc
    return top * (1 - fr) + bottom * fr


def above_ground(position_m: np.ndarray, heights: np.ndarray | None) -> np.ndarray:
    """World points (n, 3) with z taken above the terrain under each (a copy); unchanged
    without `heights` (flat ground at z 0)."""
    above = np.array(position_m, dtype=float)
    if heights is not None:
        above[:, 2] -= ground_under(heights, above[:, 0], above[:, 1])
    return above
