"""Walk's side of the AtlasSimInterface's messages: a command's step queue as footsteps, and
walk_feedback from the walk's status.

Poses are taken as ASI.md says: x, y and the yaw of the orientation, in the frame of
pos_est (the world's here); z and swing_height are ignored on flat ground. A slot with
step_index 0 is unused (a default message's queue is four of them).
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from tutorial_atlas_control.msgs import STEP_QUEUE_LENGTH, StepData, WalkFeedback
from tutorial_atlas_control.walking import SWING_HEIGHT_M, Footstep, WalkStatus

__all__ = ['footsteps_of', 'step_data_of', 'walk_feedback']


def footsteps_of(queue: Iterable[StepData]) -> list[Footstep]:
    """The used slots of walk_params.step_queue (foot indices checked by the decoder)."""
    return [Footstep(step.step_index, step.foot_index, step.position_m[0], step.position_m[1],
                     step.yaw_rad(), step.duration_s)
            for step in queue if step.step_index > 0]


def step_data_of(step: Footstep) -> StepData:
    """A footstep as AtlasBehaviorStepData: on the ground, our swing height."""
    half = 0.5 * step.yaw_rad
    return StepData(step.step_index, step.foot_index, step.duration_s, (step.x_m, step.y_m, 0.0),
                    (0.0, 0.0, math.sin(half), math.cos(half)), SWING_HEIGHT_M)


def walk_feedback(status: WalkStatus) -> WalkFeedback:
    """AtlasBehaviorWalkFeedback; step_queue_saturated padded with empty slots to four."""
    saturated = [step_data_of(step) for step in status.steps_saturated[:STEP_QUEUE_LENGTH]]
    saturated += [StepData()] * (STEP_QUEUE_LENGTH - len(saturated))
    return WalkFeedback(status.t_step_rem_s, status.current_step_index,
                        status.next_step_index_needed, status.status_flags, tuple(saturated))
