"""The model's sole boxes: which geoms they are, their size, their corners in the world.

Atlas stands on two identical boxes (sim/atlas_v1.xml), whose bottom faces are its
support: placing the robot on the ground, the support polygon, the pressure centre's
clamp and the footprints drawn from a bag all start from their corners. One definition of
the geoms, the box and the corner order, so that they all mean the same rectangle.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from tutorial_atlas_control.sim import SOLE_GEOMS

__all__ = ['BOTTOM_CORNER_SIGNS', 'ONE_SURFACE_COS', 'PRESSED_M', 'SOLE_GEOMS', 'SoleBox',
           'UPRIGHT_COS', 'box_corners', 'lowest_sole_corner_m', 'sole_corners',
           'sole_geom_ids']

# Where a sole bears (walking/sole_support.py's rule; the compiled estimate sums each sole's
# bearing contacts up with them, src/atlas_estimator.c's bearings):
#: A contact within this of its surface (m) bears on it: the estimator's reach 1 cm out, and
#: a sole on a ramp beside its bend (steps are planned clear of bends) has the other plane's
#: within that (up the pit's 22 degree ramp, counting them, the walk fell at its 8th step).
PRESSED_M = 0.002
#: Contact normals all within acos(ONE_SURFACE_COS) (2 degrees) of each other: one plane.
ONE_SURFACE_COS = 0.99939
#: A contact bears only with its normal within acos(UPRIGHT_COS) (60 degrees) of up: the
#: side of a heightfield's prism or of a block beside a sole flat on the ground (normals
#: 87-90 degrees from up, under a millimetre away) carries none of its weight, and counted,
#: made a sole on the pen's flat floor "across facets".
UPRIGHT_COS = 0.5

#: The sole boxes of the model, left then right.
#: A box's bottom-face corners as signs on its half sizes (x ahead, y left, z up): front
#: left, front right, back right, back left (counter-clockwise seen from below).
BOTTOM_CORNER_SIGNS = np.array([[1, 1, -1], [1, -1, -1], [-1, -1, -1], [-1, 1, -1]],
                               dtype=np.float64)
BOTTOM_CORNER_SIGNS.setflags(write=False)


def sole_geom_ids(model: mujoco.MjModel) -> list[int]:
    """The sole boxes' geom ids, left then right."""
    return [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name) for name in SOLE_GEOMS]


@dataclass(frozen=True)
class SoleBox:
    """A sole box of the model (the two are the same): its half sizes (m; length along the
    foot, width, thickness) and how far ahead of its foot link's origin (the ankle) its
    centre lies (m)."""

    half_length_m: float
    half_width_m: float
    half_thickness_m: float
    ahead_m: float

    @classmethod
    def of(cls, model: mujoco.MjModel) -> SoleBox:
        """The left sole's box as the model has it."""
        geom = sole_geom_ids(model)[0]
        half_length, half_width, half_thickness = (float(v) for v in model.geom_size[geom])
        return cls(half_length, half_width, half_thickness, float(model.geom_pos[geom][0]))

    @property
    def half_size_m(self) -> tuple[float, float]:
        """(half length, half width) of the bottom face (m)."""
        return self.half_length_m, self.half_width_m


def box_corners(position: np.ndarray, rotation: np.ndarray,
                half_size_m: np.ndarray | tuple[float, ...]) -> np.ndarray:
    """The bottom-face corners (4, 3) (m, world) of a box at `position` turned by `rotation`
    (3, 3) with half sizes (x, y, z); with z 0, of a face centred at `position`."""
    offsets = BOTTOM_CORNER_SIGNS * np.asarray(half_size_m, dtype=np.float64)
    return np.asarray(position) + offsets @ np.asarray(rotation).reshape(3, 3).T


def sole_corners(model: mujoco.MjModel, data: mujoco.MjData, geom_name: str) -> np.ndarray:
    """The four bottom corners (4, 3) (m, world) of a sole box, after kinematics."""
    geom = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, geom_name)
    return box_corners(data.geom_xpos[geom], data.geom_xmat[geom], model.geom_size[geom])


def lowest_sole_corner_m(model: mujoco.MjModel, data: mujoco.MjData) -> float:
    """The height (m) of the lowest bottom corner of either sole, after kinematics: how far
    to lower the robot for its feet to touch z = 0."""
    return min(float(np.min(sole_corners(model, data, name)[:, 2])) for name in SOLE_GEOMS)
