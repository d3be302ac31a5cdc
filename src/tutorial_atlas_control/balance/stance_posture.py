"""DRCSim's Stand pose carried to the stance the feet are in: the legs' joint angles that
put the pelvis, upright at a heading, where the Stand pose puts it over its feet, with each
sole where it lies.

The Stand pose is one posture, for feet side by side. In any other stance a walk or a step
leaves (staggered, turned) its legs cannot reach the soles, and Stand's posture PD on the
hips and knees, pulling towards it, pushes the soles against each other through the legs.
That squeeze is no pair of forces along the line between the soles: its moment about the
vertical is carried by the soles as torsion, which MuJoCo's soft friction yields to, so the
sole turns on the ground while Stand balances (0.32 rad in 20 s behind DRCSim's Walk queue).
The posture solved here is the one the legs have when the pelvis is held there: the PD has
nothing to push against.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from tutorial_atlas_control.balance.sole import SoleBox, sole_geom_ids
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.sim import STAND_POSE_RAD, AtlasModel

__all__ = ['Stance', 'StancePosture']

#: Each foot's leg joints, uhz to lax (tutorial order).
_LEGS = (slice(4, 10), slice(10, 16))
#: The solve stops once every sole is this near its pose (m, and rad at 1 m).
TOLERANCE_M = 1e-7
#: At most this many Newton steps: a reachable stance converges in a handful.
MAX_ITERATIONS = 30
#: A step halved below this fraction of the Newton step ends the solve.
MIN_STEP_SCALE = 1.0 / 64.0
#: The damping of the legs' least-squares steps (m): bounded steps near a straight knee.
DAMPING_M = 1e-3
#: A solved joint stays this far inside its limits (rad).
LIMIT_MARGIN_RAD = 0.01
#: Where the legs do not reach, the pelvis is lowered in steps of this (m), at most this far.
LOWERING_STEP_M = 0.005
MAX_LOWERING_M = 0.15


def _rotation_error(rotation: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The small rotation (rad, world axis) that takes `rotation` to `target`."""
    d = target @ rotation.T
    return 0.5 * np.array([d[2, 1] - d[1, 2], d[0, 2] - d[2, 0], d[1, 0] - d[0, 1]])


def _yaw_rotation(yaw_rad: float) -> np.ndarray:
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class Stance:
    """The Stand pose for one stance: its posture (28,), and how far below the Stand
    pose's (on flat ground, feet side by side) the pelvis and the centre of mass are."""

    posture_rad: np.ndarray
    pelvis_lowered_m: float
    com_lowered_m: float
    #: Whether the legs reach the soles (else the nearest they come, lowered the most).
    reached: bool


class StancePosture:
    """Solves the legs of the Stand pose for a stance, on a scratch MjData of its own."""

    def __init__(self, atlas: AtlasModel) -> None:
        self.atlas = atlas
        model = atlas.model
        self.data = mujoco.MjData(model)
        self._soles = sole_geom_ids(model)
        self._sole_bodies = [int(model.geom_bodyid[g]) for g in self._soles]
        self._half_thickness = SoleBox.of(model).half_thickness_m
        self._lower = atlas.lower_rad + LIMIT_MARGIN_RAD
        self._upper = atlas.upper_rad - LIMIT_MARGIN_RAD
        self._damping = DAMPING_M ** 2 * np.eye(6)
        self._jac = np.zeros((6, model.nv))
        # The Stand pose on flat ground, feet and pelvis facing +x: where the pelvis and the
        # centre of mass are from the soles' midpoint.
        place_in_stand_pose(atlas, self.data)
        mujoco.mj_comPos(model, self.data)
        centres, _ = self._soles_now()
        adr = atlas.free_qpos_adr
        self.pelvis_offset_m = self.data.qpos[adr:adr + 3] - centres.mean(axis=0)
        self.com_height_m = float(self.data.subtree_com[atlas.pelvis_body_id][2]
                                  - centres[:, 2].mean())

    def _soles_now(self) -> tuple[np.ndarray, np.ndarray]:
        """(centres of the soles' bottom faces (2, 3), their rotations (2, 3, 3)), world,
        after kinematics on the scratch."""
        rotations = self.data.geom_xmat[self._soles].reshape(2, 3, 3)
        centres = self.data.geom_xpos[self._soles] - rotations[:, :, 2] * self._half_thickness
        return centres, rotations

    def stance(self, sole_centres: np.ndarray, sole_rotations: np.ndarray,
               pelvis_yaw_rad: float, posture_rad: np.ndarray = STAND_POSE_RAD) -> Stance:
        """`posture_rad` with the legs' joints solved so that, the pelvis upright at
        `pelvis_yaw_rad` where the Stand pose holds it over these soles' midpoint, each
        sole lies as it does (the centres of their bottom faces `sole_centres` (2, 3) and
        their frames `sole_rotations` (2, 3, 3), world): the posture as given when it
        already does (feet as the Stand pose puts them); where the legs do not reach (a
        long stride), the pelvis lowered in steps of LOWERING_STEP_M until they do (at
        most MAX_LOWERING_M)."""
        atlas, data = self.atlas, self.data
        heading = _yaw_rotation(pelvis_yaw_rad)
        centres = np.asarray(sole_centres, dtype=float)
        middle = centres.mean(axis=0)
        adr = atlas.free_qpos_adr
        data.qpos[:] = 0.0
        data.qpos[adr:adr + 3] = middle + heading @ self.pelvis_offset_m
        half = 0.5 * pelvis_yaw_rad
        data.qpos[adr + 3:adr + 7] = (np.cos(half), 0.0, 0.0, np.sin(half))
        targets = [np.asarray(rotation, dtype=float) for rotation in sole_rotations]
        lowered = 0.0
        solved, reached = self._solve(np.asarray(posture_rad), centres, targets)
        while not reached and lowered < MAX_LOWERING_M - 1e-9:
            lowered += LOWERING_STEP_M
            data.qpos[adr + 2] -= LOWERING_STEP_M
            # From the given posture again: a failed solve leaves a knee near straight,
            # whence it does not bend back.
            solved, reached = self._solve(np.asarray(posture_rad), centres, targets)
        if lowered == 0.0:
            return Stance(solved, 0.0, 0.0, reached)
        data.qpos[atlas.qpos_adr] = solved
        mujoco.mj_kinematics(atlas.model, data)
        mujoco.mj_comPos(atlas.model, data)
        com_height = float(data.subtree_com[atlas.pelvis_body_id][2] - middle[2])
        return Stance(solved, lowered, self.com_height_m - com_height, reached)

    def _solve(self, posture: np.ndarray, centres: np.ndarray,
               targets: list[np.ndarray]) -> tuple[np.ndarray, bool]:
        """Newton steps on the legs of `posture`, the pelvis where the scratch has it: (the
        legs nearest the soles, whether every sole reached its pose). A step that does not
        bring the soles nearer is halved (near a straight knee a full one overshoots)."""
        atlas, model, data = self.atlas, self.atlas.model, self.data
        best, best_error = np.array(posture, dtype=float), np.inf
        solved, steps, scale = best.copy(), np.zeros((2, 6)), 1.0
        for _ in range(MAX_ITERATIONS):
            data.qpos[atlas.qpos_adr] = solved
            mujoco.mj_kinematics(model, data)
            now, rotations = self._soles_now()
            errors = [np.concatenate([centres[foot] - now[foot],
                                      _rotation_error(rotations[foot], targets[foot])])
                      for foot in (0, 1)]
            worst = max(float(np.max(np.abs(e))) for e in errors)
            if worst >= best_error:
                scale *= 0.5
                if scale < MIN_STEP_SCALE:
                    break
            else:
                best, best_error, scale = solved.copy(), worst, 1.0
                if worst < TOLERANCE_M:
                    return best, True
                mujoco.mj_comPos(model, data)  # mj_jac needs the frames about the CoM
                for foot, leg in enumerate(_LEGS):
                    mujoco.mj_jac(model, data, self._jac[0:3], self._jac[3:6], now[foot],
                                  self._sole_bodies[foot])
                    jacobian = self._jac[:, atlas.dof_adr[leg]]
                    steps[foot] = jacobian.T @ np.linalg.solve(
                        jacobian @ jacobian.T + self._damping, errors[foot])
            for foot, leg in enumerate(_LEGS):
                solved[leg] = np.clip(best[leg] + scale * steps[foot], self._lower[leg],
                                      self._upper[leg])
        return best, False
