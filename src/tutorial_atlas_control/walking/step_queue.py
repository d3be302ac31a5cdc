"""Walk's queue of footsteps: what clients send, merged by index, and what Walk reports.

Clients send WALK commands carrying up to four steps, some on every state message (1 kHz),
some once. The queue keeps every step by its index, a later copy of an index replacing the
earlier one (re-sending the same steps changes nothing), and forgets the steps already
taken. Walk takes step `current_step_index + 1` next and looks ahead to
`current_step_index + QUEUE_LENGTH`; `next_step_index_needed`, the window a streaming
client sends from, is the first step of those not known (that last one once all are).
A step is clamped to what the legs reach from the foot before it (`step_queue_saturated`);
two steps in a row with the same foot are inconsistent (ERROR_INCONSISTENT_STEPS,
latched: Walk returns to Stand).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, replace

from tutorial_atlas_control.walking.errors import WalkingError
from tutorial_atlas_control.walking.footsteps import (
    QUEUE_LENGTH,
    Footstep,
    side_sign,
    wrap_angle,
)
from tutorial_atlas_control.walking.status_flags import (
    ERROR_INCONSISTENT_STEPS,
    WARNING_INSUFFICIENT_STEP_DATA,
)


@dataclass(frozen=True)
class StepLimits:
    """What one step may do, in the frame of the foot it steps from (ours: BDI's library
    never published its own). Forward and back along that foot's heading (m), the distance
    across it, on the stepping foot's own side (m), and the turn (rad)."""

    forward_m: float = 0.40
    back_m: float = 0.20
    min_width_m: float = 0.16
    max_width_m: float = 0.40
    turn_rad: float = 0.40


#: The limits Walk uses unless told otherwise.
DEFAULT_LIMITS = StepLimits()


def clamp_step(step: Footstep, stance: Footstep,
               limits: StepLimits = DEFAULT_LIMITS) -> Footstep:
    """`step` moved to the nearest pose the legs reach from the stance foot `stance`."""
    x, y, yaw = clamp_pose(step.foot_index, step.x_m, step.y_m, step.yaw_rad, stance, limits)
    return replace(step, x_m=x, y_m=y, yaw_rad=yaw)


def clamp_pose(foot_index: int, x_m: float, y_m: float, yaw_rad: float, stance: Footstep,
               limits: StepLimits = DEFAULT_LIMITS) -> tuple[float, float, float]:
    """clamp_step on a pose (x, y, yaw) of foot `foot_index`, without making a Footstep
    (Walk's step adjustment clamps its landing every 1 ms of a step)."""
    c, s = math.cos(stance.yaw_rad), math.sin(stance.yaw_rad)
    dx, dy = x_m - stance.x_m, y_m - stance.y_m
    ahead, across = c * dx + s * dy, -s * dx + c * dy
    ahead = min(max(ahead, -limits.back_m), limits.forward_m)
    # The stepping foot lies on its own side of the stance foot: +y for the left one.
    width = side_sign(foot_index) * across
    across = side_sign(foot_index) * min(max(width, limits.min_width_m), limits.max_width_m)
    turn = min(max(wrap_angle(yaw_rad - stance.yaw_rad), -limits.turn_rad), limits.turn_rad)
    return (stance.x_m + c * ahead - s * across, stance.y_m + s * ahead + c * across,
            wrap_angle(stance.yaw_rad + turn))


class StepQueue:
    """The steps Walk knows, from the feet where it began (`start`: index 0 of each foot)."""

    def __init__(self, start_left: Footstep, start_right: Footstep,
                 limits: StepLimits = DEFAULT_LIMITS) -> None:
        self.limits = limits
        self.current_step_index = 0
        self.inconsistent = False
        #: Stopped: no more steps are taken than the one under way (a request for Stand).
        self.stopped = False
        #: The last pose of each foot: where it stands now (left, right).
        self.feet = [start_left, start_right]
        self._last_foot: int | None = None
        self._steps: dict[int, Footstep] = {}
        #: The step under way as Walk moved it after a push (None: as sent).
        self._adjusted: Footstep | None = None
        #: preview()'s steps until the queue changes (walk_feedback asks at every state, a
        #: streaming client re-sends the same steps at every state).
        self._preview: list[Footstep] | None = None

    @property
    def next_step_index_needed(self) -> int:
        """The first step not known after the current one, at most QUEUE_LENGTH ahead:
        1 before anything is sent, current_step_index + QUEUE_LENGTH while a client keeps
        the queue full. A streaming client sends the window from it."""
        index = self.current_step_index + 1
        while index in self._steps and index < self.current_step_index + QUEUE_LENGTH:
            index += 1
        return index

    def offer(self, steps: Iterable[Footstep]) -> None:
        """Merge a command's steps; those already taken are ignored, and all once stopped.
        Within one command the first copy of an index counts (DRCSim's actionlib server
        pads a short walk with copies of earlier steps under indices already used)."""
        if self.stopped:
            return
        merged: set[int] = set()
        for step in steps:
            index = step.step_index
            if index > self.current_step_index and index not in merged:
                if self._steps.get(index) != step:
                    self._steps[index] = step
                    self._preview = None
                merged.add(index)

    def stop(self, taking: int | None) -> None:
        """No step after `taking` (the index of the step under way; None: none is): the walk
        ends with it, and steps offered later are ignored."""
        self.stopped = True
        self._steps = {k: v for k, v in self._steps.items() if taking is not None and k <= taking}
        self._preview = None

    def preview(self) -> list[Footstep]:
        """The known steps from the next one on without a gap, up to QUEUE_LENGTH, each
        clamped from the foot it steps from. Two in a row with the same foot (or the next
        one with the foot that took the last) end the preview before the second and set
        `inconsistent`."""
        if self._preview is None:
            self._preview = self._planned()
        return list(self._preview)

    def _planned(self) -> list[Footstep]:
        """preview() made anew."""
        feet = list(self.feet)
        last_foot = self._last_foot
        planned = []
        for index in range(self.current_step_index + 1,
                           self.current_step_index + QUEUE_LENGTH + 1):
            step = self._steps.get(index)
            if step is None:
                break
            if step.foot_index == last_foot:
                self.inconsistent = True
                break
            adjusted = self._adjusted
            clamped = (adjusted if adjusted is not None and index == adjusted.step_index
                       else clamp_step(step, feet[1 - step.foot_index], self.limits))
            planned.append(clamped)
            feet[step.foot_index] = clamped
            last_foot = step.foot_index
        return planned

    def adjust(self, step: Footstep) -> None:
        """The step under way (`current_step_index + 1`) lands at `step` instead, already
        within the limits: the queue's preview says so until it is down."""
        if step.step_index != self.current_step_index + 1:
            raise WalkingError(f'step {step.step_index} is not the one under way '
                             f'({self.current_step_index + 1})')
        self._adjusted = step
        self._preview = None

    def touchdown(self, landed: Footstep) -> None:
        """Step `current_step_index + 1` is down, where `landed` says."""
        self._adjusted = None
        self._preview = None
        self.current_step_index += 1
        self.feet[landed.foot_index] = landed
        self._last_foot = landed.foot_index
        self._steps = {k: v for k, v in self._steps.items() if k > self.current_step_index}

    def status_flags(self, phase: int, preview: list[Footstep] | None = None) -> int:
        """walk_feedback.status_flags for the walk's `phase` (SWAYING, STEPPING, CATCHING);
        `preview`: this queue's preview() if the caller has just made it."""
        flags = phase
        if len(self.preview() if preview is None else preview) < QUEUE_LENGTH:
            flags |= WARNING_INSUFFICIENT_STEP_DATA
        if self.inconsistent:
            flags |= ERROR_INCONSISTENT_STEPS
        return flags
