"""atlas_msgs/AtlasSimInterfaceState (DRCSim 2.6/2.7) as wire bytes, without genpy.

The simulator publishes one every 1 ms step while someone subscribes: built from plain
values with struct, byte for byte what genpy serializes (test/unit/msgs). The feedback
numbers are the library's (ASI.md): behavior_feedback.status_flags one value at a time,
step and walk SWAYING 1 / STEPPING 2.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field

import numpy as np

from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.msgs.atlas_sim_interface import (
    STEP_QUEUE_LENGTH,
    StepData,
    step_data_bytes,
)
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['AsiState', 'BehaviorFeedback', 'ManipulateFeedback', 'StepFeedback',
           'WalkFeedback', 'encode_asi_state']

_HEADER = struct.Struct('<III')           # seq, secs, nsecs (then frame_id)
_CODES = struct.Struct('<iii')            # error_code, current_behavior, desired_behavior
_BEHAVIOR_FEEDBACK = struct.Struct('<Iii')
_STEP_FEEDBACK = struct.Struct('<IdII')   # status_flags, t_step_rem, current, next needed
_WALK_FEEDBACK = struct.Struct('<dIII')   # t_step_rem, current, next needed, status_flags
_U32 = struct.Struct('<I')
_PELVIS_SERVO = struct.Struct('<3d')
_F_OUT = struct.Struct(f'<{NUM_JOINTS}d')
_POSITION_DATA = struct.Struct('<6d')     # AtlasPositionData: position, velocity
_POSE = struct.Struct('<7d')              # geometry_msgs/Pose: position, orientation xyzw


@dataclass(frozen=True)
class BehaviorFeedback:
    """atlas_msgs/AtlasBehaviorFeedback."""

    status_flags: int = 0
    trans_from_behavior_index: int = 0
    trans_to_behavior_index: int = 0


@dataclass(frozen=True)
class StepFeedback:
    """atlas_msgs/AtlasBehaviorStepFeedback (status 1 SWAYING, 2 STEPPING)."""

    status_flags: int = 0
    t_step_rem_s: float = 0.0
    current_step_index: int = 0
    next_step_index_needed: int = 0
    desired_step_saturated: StepData = StepData()


@dataclass(frozen=True)
class WalkFeedback:
    """atlas_msgs/AtlasBehaviorWalkFeedback."""

    t_step_rem_s: float = 0.0
    current_step_index: int = 0
    next_step_index_needed: int = 0
    status_flags: int = 0
    step_queue_saturated: tuple[StepData, ...] = (StepData(),) * STEP_QUEUE_LENGTH


@dataclass(frozen=True)
class ManipulateFeedback:
    """atlas_msgs/AtlasBehaviorManipulateFeedback: the pelvis targets as clamped."""

    status_flags: int = 0
    pelvis_height_m: float = 0.0
    pelvis_yaw_rad: float = 0.0
    pelvis_lat_m: float = 0.0


def _zeros() -> np.ndarray:
    return np.zeros(NUM_JOINTS)


def _no_feet() -> np.ndarray:
    poses = np.zeros((2, 7))
    poses[:, 6] = 1.0
    return poses


@dataclass(frozen=True)
class AsiState:
    """One AtlasSimInterfaceState's values (SI units, world frame).

    `foot_poses`: (2, 7) left then right, position then quaternion (x, y, z, w);
    `k_effort`: the blend in use, (28,) uint8.
    """

    stamp_ns: int
    error_code: int = 0
    current_behavior: int = 0
    desired_behavior: int = 0
    f_out_nm: np.ndarray = field(default_factory=_zeros)
    pelvis_position_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    pelvis_velocity_m_s: tuple[float, float, float] = (0.0, 0.0, 0.0)
    foot_poses: np.ndarray = field(default_factory=_no_feet)
    behavior_feedback: BehaviorFeedback = BehaviorFeedback()
    step_feedback: StepFeedback = StepFeedback()
    stand_status_flags: int = 0
    walk_feedback: WalkFeedback = WalkFeedback()
    manipulate_feedback: ManipulateFeedback = ManipulateFeedback()
    k_effort: np.ndarray = field(default_factory=lambda: np.zeros(NUM_JOINTS, np.uint8))


def encode_asi_state(state: AsiState, seq: int = 0, frame_id: str = '') -> bytes:
    """The wire bytes of `state` (header seq `seq`)."""
    secs, nsecs = divmod(state.stamp_ns, NS_PER_S)
    frame = frame_id.encode()
    parts = [_HEADER.pack(seq, secs, nsecs), _U32.pack(len(frame)), frame,
             _CODES.pack(state.error_code, state.current_behavior, state.desired_behavior),
             _F_OUT.pack(*np.asarray(state.f_out_nm, dtype=np.float64)),
             _POSITION_DATA.pack(*state.pelvis_position_m, *state.pelvis_velocity_m_s),
             _POSE.pack(*state.foot_poses[0]), _POSE.pack(*state.foot_poses[1])]
    behavior = state.behavior_feedback
    parts.append(_BEHAVIOR_FEEDBACK.pack(behavior.status_flags,
                                         behavior.trans_from_behavior_index,
                                         behavior.trans_to_behavior_index))
    step = state.step_feedback
    parts += [_STEP_FEEDBACK.pack(step.status_flags, step.t_step_rem_s, step.current_step_index,
                                  step.next_step_index_needed),
              step_data_bytes(step.desired_step_saturated), _U32.pack(state.stand_status_flags)]
    walk = state.walk_feedback
    if len(walk.step_queue_saturated) != STEP_QUEUE_LENGTH:
        raise ValueError(f'walk_feedback.step_queue_saturated has '
                         f'{len(walk.step_queue_saturated)} steps, not {STEP_QUEUE_LENGTH}')
    parts.append(_WALK_FEEDBACK.pack(walk.t_step_rem_s, walk.current_step_index,
                                     walk.next_step_index_needed, walk.status_flags))
    parts += [step_data_bytes(s) for s in walk.step_queue_saturated]
    manipulate = state.manipulate_feedback
    parts += [_U32.pack(manipulate.status_flags),
              _PELVIS_SERVO.pack(manipulate.pelvis_height_m, manipulate.pelvis_yaw_rad,
                                 manipulate.pelvis_lat_m)]
    k_effort = np.asarray(state.k_effort, dtype=np.uint8)
    parts += [_U32.pack(len(k_effort)), k_effort.tobytes()]
    return b''.join(parts)
