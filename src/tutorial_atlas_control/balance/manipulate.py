"""Manipulate's pelvis servo: where a client asks the pelvis to be, clamped to what the legs
reach, and the posture that puts it there.

The AtlasSimInterface's Manipulate is Stand with the pelvis at `manipulate_params.desired`
(height above the soles, yaw about the feet's mean heading, lateral offset along the line
between the feet). The height comes from bending the Stand pose's legs, in two ranges:

- level: the knee by k, the hip and ankle pitches by the Stand pose's own split of it (the
  hip takes HIP_SHARE), so hip, knee and ankle pitches sum to 0 and the torso stays parallel
  to the flat feet, down to where the ankle's pitch limit ends the bend;
- tipped: below that, the ankle stays where the level range left it and the knee bends on;
  the hip flexes further so that the centre of mass stays where the deepest level bend had
  it over the soles, and the pelvis pitches forward by the pitches' sum (a squat: the thighs
  go back, the torso leans over the feet), down to the hip pitch's limit.

A table of postures against the pelvis and centre-of-mass heights, from the model's
kinematics, turns a height into a posture and a pelvis pitch. Yaw turns both hip yaw joints;
the lateral offset moves the balance's capture point. Every number here is ours: BDI never
published theirs.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from tutorial_atlas_control.balance.sole import lowest_sole_corner_m, sole_geom_ids
from tutorial_atlas_control.balance.stand_pose import STAND_POSE_RAD, place_in_stand_pose
from tutorial_atlas_control.joints import JOINT_INDEX
from tutorial_atlas_control.sim import AtlasModel

__all__ = ['HIP_SHARE', 'LATERAL_LIMIT_M', 'PelvisServo', 'SquatTable', 'bent_posture',
           'clamp_servo', 'pelvis_pitch_rad', 'place_pitched']

_LEGS = ('l', 'r')
_PITCH = {side: (JOINT_INDEX[f'{side}_leg_lhy'], JOINT_INDEX[f'{side}_leg_kny'],
                 JOINT_INDEX[f'{side}_leg_uay']) for side in _LEGS}
_HIP_YAW = tuple(JOINT_INDEX[f'{side}_leg_uhz'] for side in _LEGS)
#: The hip's share of the knee's bend in the Stand pose (the ankle takes the rest).
HIP_SHARE = float(-STAND_POSE_RAD[_PITCH['l'][0]] / STAND_POSE_RAD[_PITCH['l'][1]])
#: How far (rad) from a joint limit the servo's bend and yaw stay.
LIMIT_MARGIN_RAD = 0.05
YAW_MARGIN_RAD = 0.02
#: The lateral offset's bound (m): inside the feet's 0.125 m wide soles with room to balance.
LATERAL_LIMIT_M = 0.05
#: Knee bends tabulated (rad).
_TABLE_STEP_RAD = 0.02
#: Bisection steps for a tipped row's hip pitch (the bracket is under 2 rad: 2^-30 of it).
_HIP_BISECTIONS = 30


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


def _leg_pitches(posture: np.ndarray, hip_rad: float, knee_rad: float,
                 ankle_rad: float) -> np.ndarray:
    posture = posture.copy()
    for side in _LEGS:
        posture[list(_PITCH[side])] = (hip_rad, knee_rad, ankle_rad)
    return posture


def pelvis_pitch_rad(posture: np.ndarray) -> float:
    """The pelvis's pitch (rad, about its y axis: + leans forward) that lays the soles flat
    in `posture`: minus the sum of a leg's hip, knee and ankle pitches (0 in the level
    range)."""
    return -float(posture[list(_PITCH['l'])].sum())


def place_pitched(atlas: AtlasModel, data: mujoco.MjData,
                  joint_angles_rad: np.ndarray) -> float:
    """As place_in_stand_pose, with the pelvis pitched forward by the leg pitches' sum so that
    the soles lie flat; returns the pelvis height (m). `data` is left placed (kinematics and
    centres of mass computed)."""
    place_in_stand_pose(atlas, data, joint_angles_rad)
    pitch = pelvis_pitch_rad(joint_angles_rad)
    adr = atlas.free_qpos_adr
    data.qpos[adr + 3:adr + 7] = (np.cos(pitch / 2.0), 0.0, np.sin(pitch / 2.0), 0.0)
    mujoco.mj_kinematics(atlas.model, data)
    data.qpos[adr + 2] -= lowest_sole_corner_m(atlas.model, data)
    mujoco.mj_kinematics(atlas.model, data)
    mujoco.mj_comPos(atlas.model, data)
    return float(data.qpos[adr + 2])


def _com_ahead_m(atlas: AtlasModel, data: mujoco.MjData) -> float:
    """How far (m) the centre of mass is ahead of the soles' middle, after placing."""
    soles = sole_geom_ids(atlas.model)
    return float(data.subtree_com[atlas.pelvis_body_id][0]
                 - np.mean([data.geom_xpos[g][0] for g in soles]))


class SquatTable:
    """The postures of Manipulate's squat, level then tipped, with their pelvis pitch and
    their pelvis and centre-of-mass heights (m, above the soles), and the yaws the joint
    limits allow."""

    def __init__(self, atlas: AtlasModel) -> None:
        model = atlas.model
        ranges = np.array([model.jnt_range[model.joint(name).id]
                           for name in ('l_leg_kny', 'l_leg_uay', 'l_leg_lhy', 'l_leg_uhz',
                                        'r_leg_uhz')])
        (knee_lo, knee_hi), (ankle_lo, _), (hip_lo, _), (l_yaw_lo, _), (_, r_yaw_hi) = ranges
        deepest = min(knee_hi, -ankle_lo / (1.0 - HIP_SHARE), -hip_lo / HIP_SHARE)
        knees = np.arange(max(knee_lo, 0.0), deepest - LIMIT_MARGIN_RAD, _TABLE_STEP_RAD)
        data = mujoco.MjData(model)
        postures = [bent_posture(float(knee)) for knee in knees]
        #: How many of the rows (the first, by bend) keep the pelvis level.
        self.level_rows = len(postures)
        place_pitched(atlas, data, postures[-1])
        com_ahead = _com_ahead_m(atlas, data)
        ankle = float(postures[-1][_PITCH['l'][2]])
        hip_floor = float(hip_lo) + LIMIT_MARGIN_RAD
        for knee in np.arange(knees[-1] + _TABLE_STEP_RAD, knee_hi - LIMIT_MARGIN_RAD,
                              _TABLE_STEP_RAD):
            posture = self._tipped(atlas, data, float(knee), ankle, hip_floor, com_ahead,
                                   postures[-1])
            if posture is None:
                break
            postures.append(posture)
        pelvis, com = [], []
        for posture in postures:
            pelvis.append(place_pitched(atlas, data, posture))
            com.append(float(data.subtree_com[atlas.pelvis_body_id][2]))
        # Nearly straight knees stand a little lower than slightly bent ones: the table
        # starts at the highest bend, so that height and posture change together.
        highest = int(np.argmax(pelvis))
        postures, pelvis, com = postures[highest:], pelvis[highest:], com[highest:]
        self.level_rows -= highest
        order = np.argsort(pelvis)  # deeper bends stand lower
        self.postures_rad = np.array(postures)[order]
        self.pelvis_m = np.array(pelvis)[order]
        self.com_m = np.array(com)[order]
        self.pitch_rad = np.array([pelvis_pitch_rad(p) for p in self.postures_rad])
        self._rows = np.column_stack([self.postures_rad, self.pitch_rad, self.com_m])
        self._slopes = np.diff(self._rows, axis=0) / np.diff(self.pelvis_m)[:, None]
        #: The pelvis height (m) in the Stand pose itself.
        self.stand_height_m = place_in_stand_pose(atlas, data)
        #: The pelvis yaw (rad) both hip yaw joints allow, either way.
        self.yaw_limit_rad = float(min(-l_yaw_lo, r_yaw_hi) - YAW_MARGIN_RAD)

    @staticmethod
    def _tipped(atlas: AtlasModel, data: mujoco.MjData, knee_rad: float, ankle_rad: float,
                hip_floor_rad: float, com_ahead_m: float,
                previous: np.ndarray) -> np.ndarray | None:
        """The tipped posture at `knee_rad`: the hip pitch (bisected) that keeps the centre of
        mass `com_ahead_m` ahead of the soles; None when it would pass `hip_floor_rad`."""
        def ahead(hip_rad: float) -> float:
            place_pitched(atlas, data, _leg_pitches(previous, hip_rad, knee_rad, ankle_rad))
            return _com_ahead_m(atlas, data) - com_ahead_m

        low, high = hip_floor_rad, float(previous[_PITCH['l'][0]])
        if ahead(low) < 0.0:  # even the deepest hip flexion leaves the mass behind
            return None
        for _ in range(_HIP_BISECTIONS):  # flexing the hip moves the mass forward
            middle = 0.5 * (low + high)
            if ahead(middle) > 0.0:
                low = middle
            else:
                high = middle
        return _leg_pitches(previous, 0.5 * (low + high), knee_rad, ankle_rad)

    @property
    def height_range_m(self) -> tuple[float, float]:
        return float(self.pelvis_m[0]), float(self.pelvis_m[-1])

    @property
    def level_floor_m(self) -> float:
        """The lowest pelvis height (m) with the pelvis level."""
        return float(self.pelvis_m[-self.level_rows])

    def row(self, pelvis_height_m: float) -> tuple[np.ndarray, np.ndarray]:
        """The table at `pelvis_height_m` (within range), interpolated: (the posture (28,)
        then the pelvis pitch (rad) then the CoM height (m), as one (30,) vector; its
        derivative per metre of pelvis height)."""
        heights = self.pelvis_m
        index = int(np.clip(np.searchsorted(heights, pelvis_height_m), 1, len(heights) - 1))
        below, above = heights[index - 1], heights[index]
        weight = float(np.clip((pelvis_height_m - below) / (above - below), 0.0, 1.0))
        rows = self._rows
        slope = self._slopes[index - 1]
        return rows[index - 1] + weight * (above - below) * slope, slope

    def posture_for(self, pelvis_height_m: float, yaw_rad: float = 0.0) -> np.ndarray:
        """The posture (28,) that puts the pelvis at `pelvis_height_m` (within range), both
        hip yaws turning it by `yaw_rad`."""
        posture = self.row(pelvis_height_m)[0][:28].copy()
        posture[list(_HIP_YAW)] = -yaw_rad
        return posture

    def knee_for(self, pelvis_height_m: float) -> float:
        """The knee bend (rad) that puts the pelvis at `pelvis_height_m` (within range)."""
        return float(self.row(pelvis_height_m)[0][_PITCH['l'][1]])

    def pitch_for(self, pelvis_height_m: float) -> float:
        """The pelvis's forward pitch (rad) at `pelvis_height_m` (0 in the level range)."""
        return float(self.row(pelvis_height_m)[0][28])

    def com_for(self, pelvis_height_m: float) -> float:
        """The centre of mass's height (m) with the pelvis at `pelvis_height_m`."""
        return float(self.row(pelvis_height_m)[0][29])


def clamp_servo(desired: PelvisServo, table: SquatTable) -> PelvisServo:
    """`desired` clamped to what the robot can reach (manipulate_feedback.clamped); a NaN
    never gets here (the command decoder refuses it)."""
    low, high = table.height_range_m
    yaw = table.yaw_limit_rad
    return PelvisServo(float(np.clip(desired.height_m, low, high)),
                       float(np.clip(desired.yaw_rad, -yaw, yaw)),
                       float(np.clip(desired.lateral_m, -LATERAL_LIMIT_M, LATERAL_LIMIT_M)))
