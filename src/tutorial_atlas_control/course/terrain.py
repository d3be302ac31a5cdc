"""The course's terrain as heights: the package's terrain image with course.HEIGHTMAP's
scaling, the image the world's heightfield is made of (tools/make_vrc_world.py).

Read once a process and shared: a recorded run's analysis (the ground under a fall, the
landings, the map), a walker's way over the hills (hill_way.py) and the live course walker's
strides on the ground (cli/vrc_walker.py) ask for it.
"""

from __future__ import annotations

import functools

import numpy as np

from tutorial_atlas_control.course.starts import TERRAIN_FILE
from tutorial_atlas_control.course.vrc_task_2 import HEIGHTMAP, MUD_FLOOR_Z_M, PEN
from tutorial_atlas_control.grids import grid_bilinear
from tutorial_atlas_control.resources import package_path

__all__ = ['course_height_m', 'ground_under', 'terrain_heights']


@functools.cache
def terrain_heights() -> np.ndarray:
    """The course's terrain heights (m), rows from +y down, columns from -x (the image's
    layout), read-only."""
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
    return grid_bilinear(heights, row, col)


def course_height_m(x_m: float, y_m: float) -> float:
    """The ground's height (m) under one world point: the terrain, the mud pit's floor plane
    (MUD_FLOOR_Z_M, 1 cm over the terrain's deepest) and the pen's floor: the ground a walker
    plans on when it knows the world only from its description (walking/route.py's
    `ground`)."""
    height = max(float(ground_under(terrain_heights(), np.asarray(x_m), np.asarray(y_m))),
                 MUD_FLOOR_Z_M)
    (cx, cy, cz), (sx, sy, sz) = PEN.centre_m, PEN.size_m
    if abs(x_m - cx) <= sx / 2 and abs(y_m - cy) <= sy / 2:
        height = max(height, cz + sz / 2)
    return height
