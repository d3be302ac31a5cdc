"""Where a step's sole comes to rest on a heightfield: the plane over its footprint.

The VRC course's terrain is a heightfield of 0.195 m cells whose heights come in steps of
1.4 cm (a grey level of its image): under a sole (0.26 x 0.13 m) lie up to eight triangles,
whose normals scatter by several degrees about the hill's slope. The normal of the one
triangle under the sole's centre made the swing lay the sole on a facet the sole does not
rest on: on the hills a landing touched on an edge, rolled 0.4 rad and bounced 12 cm away.
Here the surface is fitted to the ground under the sole's four corners and centre (least
squares), and raised until no sampled point is above it: the plane the sole rests on, its
highest points first. Only on a heightfield, with all five points on it; elsewhere (a
plane, a box, a cinder block's top, a sole over an edge) the ground under the centre.
"""

from __future__ import annotations

import math

import numpy as np

from tutorial_atlas_control.balance import BOTTOM_CORNER_SIGNS
from tutorial_atlas_control.sim import Ground

__all__ = ['footprint_surface']

#: The sole's bottom face sampled: its corners (along, across, in half sizes; sole.py's
#: order) and, last, its centre.
_SAMPLES = np.vstack([BOTTOM_CORNER_SIGNS[:, :2], np.zeros((1, 2))])


def footprint_surface(ground: Ground, x_m: float, y_m: float, yaw_rad: float,
                      half_size_m: tuple[float, float], centre_height_m: float
                      ) -> tuple[float, tuple[float, float, float]] | None:
    """The height (m) at (`x_m`, `y_m`) and the unit normal of the plane a sole of
    `half_size_m` (along, across) heading `yaw_rad` rests on there, when the ground under
    its corners is all one of `ground`'s heightfields (the caller has found its centre on
    one, at `centre_height_m`); else None."""
    cos, sin = math.cos(yaw_rad), math.sin(yaw_rad)
    offsets = _SAMPLES * np.asarray(half_size_m, dtype=float)
    dx = offsets[:, 0] * cos - offsets[:, 1] * sin
    dy = offsets[:, 0] * sin + offsets[:, 1] * cos
    heights = np.empty(len(offsets))
    heights[-1] = centre_height_m
    for row in range(len(offsets) - 1):
        hit = ground.hit(x_m + float(dx[row]), y_m + float(dy[row]))
        if hit.geom_id not in ground.hfield_geoms:
            return None
        heights[row] = hit.height_m
    design = np.column_stack([np.ones(len(offsets)), dx, dy])
    (offset_m, slope_x, slope_y), *_ = np.linalg.lstsq(design, heights, rcond=None)
    lift_m = float(np.max(heights - design @ np.array([offset_m, slope_x, slope_y])))
    norm = math.sqrt(slope_x * slope_x + slope_y * slope_y + 1.0)
    return (float(offset_m) + lift_m,
            (float(-slope_x / norm), float(-slope_y / norm), float(1.0 / norm)))
