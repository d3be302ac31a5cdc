"""Manipulate's pelvis servo: where a client asks the pelvis to be, clamped to what the legs
reach, and the posture that puts it there.

The AtlasSimInterface's Manipulate is Stand with the pelvis at `manipulate_params.desired`
(height above the soles, yaw about the feet's mean heading, lateral offset along the line
between the feet). The height comes from bending the Stand pose's legs: the knee by k, the
hip and ankle pitches by the Stand pose's own split of it (the hip takes HIP_SHARE), so hip,
knee and ankle pitches still sum to about 0 and the torso stays parallel to the flat feet. A
table of k against the pelvis and centre-of-mass heights, from the model's kinematics, turns
a height into a bend. Yaw turns both hip yaw joints; the lateral offset moves the balance's
capture point. Every number here is ours: BDI never published theirs.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from tutorial_atlas_control.balance.stand_pose import STAND_POSE_RAD, place_in_stand_pose
from tutorial_atlas_control.joints import JOINT_INDEX
from tutorial_atlas_control.sim import AtlasModel

__all__ = ['HIP_SHARE', 'LATERAL_LIMIT_M', 'PelvisServo', 'SquatTable', 'bent_posture',
           'clamp_servo']

_LEGS = ('l', 'r')
_PITCH = {side: (JOINT_INDEX[f'{side}_leg_lhy'], JOINT_INDEX[f'{side}_leg_kny'],
                 JOINT_INDEX[f'{side}_leg_uay']) for side in _LEGS}
_HIP_YAW = tuple(JOINT_INDEX[f'{side}_leg_uhz'] for side in _LEGS)
#: The hip's share of the knee's bend in the Stand pose (the ankle takes the rest).
HIP_SHARE = float(-STAND_POSE_RAD[_PITCH['l'][0]] / STAND_POSE_RAD[_PITCH['l'][1]])
#: How far (rad) from a joint limit the servo's knee bend and yaw stay.
LIMIT_MARGIN_RAD = 0.05
YAW_MARGIN_RAD = 0.02
#: The lateral offset's bound (m): inside the feet's 0.125 m wide soles with room to balance.
LATERAL_LIMIT_M = 0.05
#: Knee bends tabulated (rad).
_TABLE_STEP_RAD = 0.02


@dataclass(frozen=True)
class PelvisServo:
    """atlas_msgs/AtlasBehaviorPelvisServoParams: the pelvis's height above the soles (m),
    its yaw about the feet's mean heading (rad) and its offset along the line between the
    feet (m, + to the left foot)."""

    height_m: float
    yaw_rad: float = 0.0
    lateral_m: float = 0.0


def bent_posture(knee_rad: float, yaw_rad: float = 0.0) -> np.ndarray:
    """The Stand pose with each knee at `knee_rad`, hips and ankles pitched to keep the torso
    parallel to the feet, and both hip yaws turning the pelvis by `yaw_rad`."""
    posture = STAND_POSE_RAD.copy()
    for side in _LEGS:
        hip, knee, ankle = _PITCH[side]
        posture[hip] = -HIP_SHARE * knee_rad
        posture[knee] = knee_rad
        posture[ankle] = -(1.0 - HIP_SHARE) * knee_rad
    posture[list(_HIP_YAW)] = -yaw_rad
    return posture


class SquatTable:
    """The pelvis and centre-of-mass heights (m, above the soles) of the bent Stand pose, per
    knee bend, and the bends and yaws the joint limits allow."""

    def __init__(self, atlas: AtlasModel) -> None:
        model = atlas.model
        ranges = np.array([model.jnt_range[model.joint(name).id]
                           for name in ('l_leg_kny', 'l_leg_uay', 'l_leg_lhy', 'l_leg_uhz',
                                        'r_leg_uhz')])
        (knee_lo, knee_hi), (ankle_lo, _), (hip_lo, _), (l_yaw_lo, _), (_, r_yaw_hi) = ranges
        deepest = min(knee_hi, -ankle_lo / (1.0 - HIP_SHARE), -hip_lo / HIP_SHARE)
        knees = np.arange(max(knee_lo, 0.0), deepest - LIMIT_MARGIN_RAD, _TABLE_STEP_RAD)
        data = mujoco.MjData(model)
        pelvis, com = [], []
        for knee in knees:
            pelvis.append(place_in_stand_pose(atlas, data, bent_posture(float(knee))))
            mujoco.mj_comPos(model, data)
            com.append(float(data.subtree_com[0][2]))
        order = np.argsort(pelvis)  # straighter knees stand higher
        self.knee_rad = knees[order]
        self.pelvis_m = np.array(pelvis)[order]
        self.com_m = np.array(com)[order]
        #: The pelvis height (m) in the Stand pose itself.
        self.stand_height_m = place_in_stand_pose(atlas, data)
        #: The pelvis yaw (rad) both hip yaw joints allow, either way.
        self.yaw_limit_rad = float(min(-l_yaw_lo, r_yaw_hi) - YAW_MARGIN_RAD)

    @property
    def height_range_m(self) -> tuple[float, float]:
        return float(self.pelvis_m[0]), float(self.pelvis_m[-1])

    def knee_for(self, pelvis_height_m: float) -> float:
        """The knee bend (rad) that puts the pelvis at `pelvis_height_m` (within range)."""
        return float(np.interp(pelvis_height_m, self.pelvis_m, self.knee_rad))

    def com_for(self, pelvis_height_m: float) -> float:
        """The centre of mass's height (m) with the pelvis at `pelvis_height_m`."""
        return float(np.interp(pelvis_height_m, self.pelvis_m, self.com_m))


def clamp_servo(desired: PelvisServo, table: SquatTable) -> PelvisServo:
    """`desired` clamped to what the robot can reach (manipulate_feedback.clamped); a NaN
    never gets here (the command decoder refuses it)."""
    low, high = table.height_range_m
    yaw = table.yaw_limit_rad
    return PelvisServo(float(np.clip(desired.height_m, low, high)),
                       float(np.clip(desired.yaw_rad, -yaw, yaw)),
                       float(np.clip(desired.lateral_m, -LATERAL_LIMIT_M, LATERAL_LIMIT_M)))
