"""The arms under the user's PID while a behaviour drives the rest (mixed control): a
JointCommands for the arm joints with the parameter gains and k_effort 255 on them, as an
AtlasCommand would set, swung about the Stand pose."""

from __future__ import annotations

import math

import numpy as np

from tutorial_atlas_control.command import K_EFFORT_ROW, CommandUpdate, command_update
from tutorial_atlas_control.joints import JOINT_INDEX, JOINT_NAMES
from tutorial_atlas_control.sim import STAND_POSE_RAD, Gains

ARMS = [name for name in JOINT_NAMES if '_arm_' in name]
_ARM_INDICES = np.array([JOINT_INDEX[name] for name in ARMS])


def arm_command(positions: np.ndarray, gains: Gains) -> list[CommandUpdate]:
    """The updates that put the arms at `positions` ((28,), rad) under the user's PID."""
    arms = _ARM_INDICES
    zeros = np.zeros(len(arms))
    return [command_update(ARMS, {
        'position': positions[arms], 'velocity': zeros, 'effort': zeros,
        'kp_position': gains.p[arms], 'ki_position': gains.i[arms], 'kd_position': gains.d[arms],
        'kp_velocity': zeros, 'i_effort_min': -gains.i_clamp[arms],
        'i_effort_max': gains.i_clamp[arms]}),
        CommandUpdate(arms, (K_EFFORT_ROW,), np.ones((1, len(arms))))]


def swung(joint: str, range_rad: float, frequency_hz: float, time_s: float) -> np.ndarray:
    """The Stand pose with both arms' `joint` (e.g. 'usy') swung through `range_rad`."""
    target = STAND_POSE_RAD.copy()
    for side in 'lr':
        target[JOINT_INDEX[f'{side}_arm_{joint}']] += (
            range_rad / 2 * math.sin(2 * math.pi * frequency_hz * time_s))
    return target
