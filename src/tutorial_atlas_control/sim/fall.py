"""When the robot has fallen, said once for every tool: its pelvis less than FALL_HEIGHT_M
above the ground under its feet.

The simulator's fall line, the bag analysis and its plots, a sweep run's fall time, the
AtlasSimInterface's Freeze of a walk that fell and the mode-switching demo all ask this
one question (`fallen`). Two other questions keep their own names because they are asked
earlier, on purpose: `falling` (the AtlasSimInterface's standing behaviours report
ERROR_FALLING) and `standing` (a push or walk trial's "still standing").

"The ground under its feet" is the ground (sim/ground.py) under the centre of the lower
sole: the lower foot is the one on the ground (a swing foot is lifted), so stepping up a
block, with the stance foot still below, the pelvis is measured from where the robot
stands; the soles' midpoint could fall on a block's edge or into a gap between the feet.
On level ground (today's plane at z = 0) the ground's height is that plane's, read without
rays, so every figure is the one the absolute thresholds gave. Recorded bags have no
world: they use the flat-ground form, the functions' ground height 0.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # the flat-ground form (bag analysis) loads no MuJoCo
    import mujoco

    from tutorial_atlas_control.sim.ground import Ground
    from tutorial_atlas_control.sim.model import AtlasModel

__all__ = ['FALLING_PELVIS_M', 'FALLING_TILT_RAD', 'FALL_HEIGHT_M', 'STANDING_PELVIS_M',
           'GroundUnderFeet', 'fallen', 'fallen_samples', 'falling', 'standing']

#: The robot has fallen once its pelvis is less than this (m) above the ground under its
#: feet (standing, the pelvis is about 0.92 m above the soles; on hands and knees, lower).
FALL_HEIGHT_M = 0.5
#: A standing behaviour is falling once its pelvis is less than this (m) above the ground
#: (Stand holds it 0.91 m up) ...
FALLING_PELVIS_M = 0.7
#: ... or its pelvis is tilted more than this (rad) from upright (the world's z: a robot
#: on a slope still stands upright).
FALLING_TILT_RAD = 0.5
#: A trial's robot is still standing while its pelvis stays at least this (m) above the
#: ground (Stand holds it 0.91 m up).
STANDING_PELVIS_M = 0.8


def fallen(pelvis_z_m: float, ground_z_m: float = 0.0) -> bool:
    """The pelvis at world height `pelvis_z_m` less than FALL_HEIGHT_M above the ground at
    `ground_z_m` (0: the flat-ground form, for bags recorded without a world)."""
    return pelvis_z_m - ground_z_m < FALL_HEIGHT_M


def fallen_samples(pelvis_z_m: np.ndarray, ground_z_m: float | np.ndarray = 0.0,
                   ) -> np.ndarray:
    """`fallen` sample by sample (a recorded series): a boolean array."""
    return np.asarray(pelvis_z_m) - ground_z_m < FALL_HEIGHT_M


def falling(pelvis_z_m: float, pelvis_up_z: float, ground_z_m: float = 0.0) -> bool:
    """A standing behaviour falling: the pelvis less than FALLING_PELVIS_M above the ground
    or tilted more than FALLING_TILT_RAD (`pelvis_up_z`: its z axis's world z). Earlier
    than `fallen` on purpose, and with the tilt: the AtlasSimInterface's ERROR_FALLING warns
    a client while the robot may still be caught; it ends nothing (a walk goes on; `fallen`
    Freezes it)."""
    tilt = math.acos(max(-1.0, min(1.0, pelvis_up_z)))
    return pelvis_z_m - ground_z_m < FALLING_PELVIS_M or tilt > FALLING_TILT_RAD


def standing(pelvis_z_m: float, ground_z_m: float = 0.0) -> bool:
    """A trial's robot still standing: the pelvis at least STANDING_PELVIS_M above the
    ground. Stricter than not `fallen`: a push the Stand survives only by sinking 10 cm
    has not been withstood (the trials' figures count it lost)."""
    return not pelvis_z_m - ground_z_m < STANDING_PELVIS_M


class GroundUnderFeet:
    """The ground under a simulated robot's lower sole, and the predicates above measured
    from it; `ground` defaults to the world of `atlas`'s model, loose bodies from `data`."""

    def __init__(self, atlas: AtlasModel, data: mujoco.MjData,
                 ground: Ground | None = None) -> None:
        from tutorial_atlas_control.sim.ground import Ground  # noqa: PLC0415 - bags: no MuJoCo
        from tutorial_atlas_control.sim.model import SOLE_GEOMS  # noqa: PLC0415 - the same
        self.data = data
        self.ground = ground if ground is not None else Ground(atlas.model, data)
        self._soles = [atlas.model.geom(name).id for name in SOLE_GEOMS]
        self._pelvis = atlas.pelvis_body_id
        self._pelvis_z = atlas.free_qpos_adr + 2

    def pelvis_z_m(self) -> float:
        """The pelvis's world height (m) in qpos (sim/model.py's pelvis_height_m)."""
        return float(self.data.qpos[self._pelvis_z])

    def height_m(self) -> float:
        """The ground's height (m) under the lower sole's centre (the soles as the last
        mj_forward/mj_step placed them)."""
        level = self.ground.level_m
        if level is not None:
            return level
        left, right = (self.data.geom_xpos[sole] for sole in self._soles)
        x, y, _ = (left if left.item(2) <= right.item(2) else right).tolist()
        return self.ground.height_m(x, y)

    def clearance_m(self, pelvis_z_m: float | None = None) -> float:
        """How high (m) the pelvis (at world height `pelvis_z_m`, else qpos's) is above the
        ground."""
        return (self.pelvis_z_m() if pelvis_z_m is None else pelvis_z_m) - self.height_m()

    def fallen(self, pelvis_z_m: float | None = None) -> bool:
        """`fallen` for the pelvis at world height `pelvis_z_m` (else qpos's); no ray while
        the pelvis is FALL_HEIGHT_M above the world's highest ground."""
        if pelvis_z_m is None:
            pelvis_z_m = self.pelvis_z_m()
        if self.ground.level_m is None and self.ground.clear_above(pelvis_z_m, FALL_HEIGHT_M):
            return False
        return fallen(pelvis_z_m, self.height_m())

    def falling(self) -> bool:
        """`falling` for the pelvis as the last mj_forward/mj_step placed it (xpos, xmat)."""
        pelvis = self._pelvis
        return falling(float(self.data.xpos[pelvis][2]), float(self.data.xmat[pelvis][8]),
                       self.height_m())

    def standing(self, pelvis_z_m: float | None = None) -> bool:
        """`standing` for the pelvis at world height `pelvis_z_m` (else qpos's)."""
        return standing(self.pelvis_z_m() if pelvis_z_m is None else pelvis_z_m,
                        self.height_m())
