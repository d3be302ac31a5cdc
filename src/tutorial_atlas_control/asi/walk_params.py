"""Walk's and Step's side of the AtlasSimInterface's messages: a command's step queue or
desired step as footsteps, and walk_feedback and step_feedback from their status.

Poses are taken as ASI.md says: x, y and the yaw of the orientation, in the frame of
pos_est (the world's here); z and swing_height are ignored on flat ground. A step's pose is
the foot link's, the point foot_pos_est reports (so a step to where foot_pos_est says a
foot is steps in place, and DRCSim's fixed queue's 0.2 m are the ankles' strides); the
walk places sole centres, `sole_ahead_m` ahead of it along the foot. A slot with
step_index 0 is unused (a default message's queue is four of them).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Sequence
from dataclasses import replace

from tutorial_atlas_control.asi.behaviors import Behavior
from tutorial_atlas_control.msgs import (
    STEP_QUEUE_LENGTH,
    AsiCommand,
    ManipulateParams,
    StepData,
    StepFeedback,
    WalkFeedback,
)
from tutorial_atlas_control.walking import SWING_HEIGHT_M, Footstep, StepStatus, WalkStatus

__all__ = ['footsteps_of', 'sole_step', 'step_data_of', 'step_feedback', 'walk_command',
           'walk_feedback']


def _ahead(x_m: float, y_m: float, yaw_rad: float, ahead_m: float) -> tuple[float, float]:
    """The point `ahead_m` ahead of (x, y) along the heading `yaw_rad`."""
    return x_m + ahead_m * math.cos(yaw_rad), y_m + ahead_m * math.sin(yaw_rad)


def sole_step(step: Footstep, sole_ahead_m: float) -> Footstep:
    """A step of the foot link as the step of its sole's centre."""
    x, y = _ahead(step.x_m, step.y_m, step.yaw_rad, sole_ahead_m)
    return replace(step, x_m=x, y_m=y)


def footsteps_of(queue: Iterable[StepData], sole_ahead_m: float) -> list[Footstep]:
    """The used slots of walk_params.step_queue (foot indices checked by the decoder), as
    the soles' steps."""
    steps = []
    for step in queue:
        if step.step_index > 0:
            # sole_step, without a Footstep of the link first: a streaming client sends
            # four steps at every state.
            yaw = step.yaw_rad()
            x, y = _ahead(step.position_m[0], step.position_m[1], yaw, sole_ahead_m)
            steps.append(Footstep(step.step_index, step.foot_index, x, y, yaw, step.duration_s))
    return steps


@functools.lru_cache(maxsize=64)
def step_data_of(step: Footstep, sole_ahead_m: float) -> StepData:
    """A sole's step as the foot link's AtlasBehaviorStepData: on the ground, our swing
    height. Cached: walk_feedback reports the same four steps at every state."""
    link = sole_step(step, -sole_ahead_m)
    half = 0.5 * step.yaw_rad
    return StepData(step.step_index, step.foot_index, step.duration_s, (link.x_m, link.y_m, 0.0),
                    (0.0, 0.0, math.sin(half), math.cos(half)), SWING_HEIGHT_M)


def walk_command(link_steps: Sequence[Footstep]) -> AsiCommand:
    """A WALK of up to four steps, each at its foot link's pose (as WalkClient gives them),
    the rest of the queue empty: what an offline client applies to the interface."""
    if len(link_steps) > STEP_QUEUE_LENGTH:
        raise ValueError(f'a WALK carries at most {STEP_QUEUE_LENGTH} steps, '
                         f'not {len(link_steps)}')
    queue = [step_data_of(step, 0.0) for step in link_steps]
    queue += [StepData()] * (STEP_QUEUE_LENGTH - len(queue))
    return AsiCommand(0, Behavior.WALK, tuple(queue), False, StepData(), False,
                      ManipulateParams(), None, 0)


def walk_feedback(status: WalkStatus, sole_ahead_m: float) -> WalkFeedback:
    """AtlasBehaviorWalkFeedback; step_queue_saturated padded with empty slots to four."""
    saturated = [step_data_of(step, sole_ahead_m)
                 for step in status.steps_saturated[:STEP_QUEUE_LENGTH]]
    saturated += [StepData()] * (STEP_QUEUE_LENGTH - len(saturated))
    return WalkFeedback(status.t_step_rem_s, status.current_step_index,
                        status.next_step_index_needed, status.status_flags, tuple(saturated))


def step_feedback(status: StepStatus, sole_ahead_m: float) -> StepFeedback:
    """AtlasBehaviorStepFeedback; desired_step_saturated empty before the first step."""
    saturated = (StepData() if status.step_saturated is None
                 else step_data_of(status.step_saturated, sole_ahead_m))
    return StepFeedback(status.status_flags, status.t_step_rem_s, status.current_step_index,
                        status.next_step_index_needed, saturated)
