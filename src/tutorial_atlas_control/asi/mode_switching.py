"""DRCSim's mode-switching demo: the user's PID and the behaviour library mixed, 2 s apart.

DRC-era users drove Atlas this way: an AtlasCommand to all zeros with k_effort 255 (the
PID alone), DRCSim's gains, kd 0 and kp_velocity 50; one to the stand-prep pose with the
same gains; StandPrep asked for with k_effort 255 (the PID keeps the robot); Stand with
k_effort 0 (the library takes it); the neck, elbows and wrists back under the PID while
Stand balances; one four-step Walk sent once with those k_effort, its steps turned into the
world by the pelvis's pose; then every joint back to the PID at zeros.

The cues are pure: each gives the messages to send (topic, wire bytes) from the sim time and
the pelvis's pose then, so the offline test and a live client send the same bytes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from tutorial_atlas_control import topics
from tutorial_atlas_control.asi.behaviors import Behavior
from tutorial_atlas_control.asi.errors import AsiInputError
from tutorial_atlas_control.joints import JOINT_INDEX, NUM_JOINTS
from tutorial_atlas_control.msgs import (
    AsiCommand,
    ManipulateParams,
    StepData,
    encode_asi_command,
    encode_atlas_command,
)
from tutorial_atlas_control.walking import straight_steps

__all__ = ['CUES', 'KP_VELOCITY', 'MIXED_JOINTS', 'STAND_PREP_POSE', 'Cue', 'cue_messages',
           'mixed_k_effort']

#: The demo's velocity gain (N m s/rad): DRCSim 2.7 passed it through to joint damping.
KP_VELOCITY = 50.0
#: DRCSim's stand-prep pose (rad); every other joint 0.
STAND_PREP_POSE: dict[str, float] = {
    'l_leg_kny': 0.518, 'r_leg_kny': 0.518, 'l_leg_lhy': -0.233, 'r_leg_lhy': -0.233,
    'l_leg_uay': -0.276, 'r_leg_uay': -0.276, 'l_leg_mhx': 0.062, 'r_leg_mhx': -0.062,
    'l_arm_usy': 0.30, 'r_arm_usy': 0.30, 'l_arm_shx': -1.30, 'r_arm_shx': 1.30,
    'l_arm_ely': 2.0, 'r_arm_ely': 2.0, 'l_arm_elx': 0.50, 'r_arm_elx': -0.50}
#: The joints the user's PID keeps while Stand and Walk drive the rest.
MIXED_JOINTS = ('neck_ay', 'l_arm_ely', 'r_arm_ely', 'l_arm_mwx', 'r_arm_mwx')
#: The walk: steps, stride (m), feet apart (m), each step's duration (s).
WALK_STEPS = 4
WALK_STRIDE_M = 0.25
WALK_WIDTH_M = 0.30
WALK_STEP_S = 0.63


@dataclass(frozen=True)
class Cue:
    """One command of the demo: `at_s` from its start, `name` as logged."""

    at_s: float
    name: str


#: The demo, 2 s apart as DRCSim's (StandPrep to Stand 1 s; the walk takes about 4 s).
CUES = (Cue(0.0, 'zeros'), Cue(2.0, 'stand-prep pose'), Cue(4.0, 'STAND_PREP'),
        Cue(5.0, 'STAND'), Cue(7.0, 'STAND, arms and neck to the PID'), Cue(9.0, 'WALK'),
        Cue(15.0, 'USER, zeros'))
#: How long after the last cue the demo watches the robot stand (s).
AFTER_LAST_S = 3.0


def mixed_k_effort() -> bytes:
    """k_effort 255 on MIXED_JOINTS, 0 elsewhere (tutorial order)."""
    return bytes(255 if name in MIXED_JOINTS else 0 for name in JOINT_INDEX)


def _atlas_command(stamp_ns: int, position: Sequence[float], kp_position: Sequence[float],
                   kp_velocity: float) -> bytes:
    zeros = [0.0] * NUM_JOINTS
    return encode_atlas_command(stamp_ns, {
        'position': list(position), 'velocity': zeros, 'effort': zeros,
        'kp_position': list(kp_position), 'ki_position': zeros, 'kd_position': zeros,
        'kp_velocity': [kp_velocity] * NUM_JOINTS, 'i_effort_min': zeros,
        'i_effort_max': zeros, 'k_effort': [255] * NUM_JOINTS})


def _asi_command(stamp_ns: int, behavior: int, k_effort: bytes,
                 steps: tuple[StepData, ...] = (StepData(),) * 4) -> bytes:
    return encode_asi_command(AsiCommand(stamp_ns, behavior, steps, False, StepData(), False,
                                         ManipulateParams(), None, len(k_effort)), k_effort)


def walk_steps(pelvis_x_m: float, pelvis_y_m: float, yaw_rad: float) -> tuple[StepData, ...]:
    """The four steps, straight ahead of the pelvis's pose, in the world."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    half = (0.0, 0.0, math.sin(yaw_rad / 2.0), math.cos(yaw_rad / 2.0))
    return tuple(StepData(step.step_index, step.foot_index, WALK_STEP_S,
                          (pelvis_x_m + c * step.x_m - s * step.y_m,
                           pelvis_y_m + s * step.x_m + c * step.y_m, 0.0), half, 0.0)
                 for step in straight_steps(WALK_STEPS, WALK_STRIDE_M, width_m=WALK_WIDTH_M))


def cue_messages(cue: Cue, stamp_ns: int, kp_position: Sequence[float],
                 pelvis_xy_yaw: tuple[float, float, float],
                 kp_velocity: float = KP_VELOCITY) -> list[tuple[str, bytes]]:
    """The messages `cue` sends (topic, wire bytes without the length prefix), stamped
    `stamp_ns`, with the position gains `kp_position` (28, tutorial order), the pelvis's
    (x, y, yaw) now (the walk's steps are placed from it) and the velocity gain."""
    zeros = [0.0] * NUM_JOINTS
    every = bytes([255] * NUM_JOINTS)
    if cue.name == 'zeros':
        return [(topics.ATLAS_COMMAND, _atlas_command(stamp_ns, zeros, kp_position, kp_velocity))]
    if cue.name == 'stand-prep pose':
        pose = [STAND_PREP_POSE.get(name, 0.0) for name in JOINT_INDEX]
        return [(topics.ATLAS_COMMAND, _atlas_command(stamp_ns, pose, kp_position, kp_velocity))]
    if cue.name == 'STAND_PREP':
        return [(topics.ASI_COMMAND, _asi_command(stamp_ns, Behavior.STAND_PREP, every))]
    if cue.name == 'STAND':
        return [(topics.ASI_COMMAND, _asi_command(stamp_ns, Behavior.STAND,
                                                  bytes(NUM_JOINTS)))]
    if cue.name == 'STAND, arms and neck to the PID':
        return [(topics.ASI_COMMAND, _asi_command(stamp_ns, Behavior.STAND, mixed_k_effort()))]
    if cue.name == 'WALK':
        return [(topics.ASI_COMMAND, _asi_command(stamp_ns, Behavior.WALK, mixed_k_effort(),
                                                  walk_steps(*pelvis_xy_yaw)))]
    if cue.name == 'USER, zeros':
        return [(topics.ASI_COMMAND, _asi_command(stamp_ns, Behavior.USER, every)),
                (topics.ATLAS_COMMAND, _atlas_command(stamp_ns, zeros, kp_position, kp_velocity))]
    raise AsiInputError(f'unknown cue {cue.name!r}')
