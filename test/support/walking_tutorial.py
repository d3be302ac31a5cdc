"""The gazebo_tutorials Atlas walking tutorial's two clients, re-created from their
description, ROS-free: what each sends on every AtlasSimInterfaceState.

Both walk counter-clockwise round a circle of CIRCLE_R_M, 60 steps a turn, the feet
STRIDE_WIDTH_M apart across it (the left one inside), from where the pelvis was in the
first state they saw; poses are the foot links' (x, y, the yaw as a quaternion, z 0).
- The static client sends, on every state, a STEP whose desired_step has step_index 1, the
  foot of its counter (counter % 2, 0 left), 0.63 s, swing height 0.1 m, and the counter's
  pose; its counter starts at 0 and goes up by one each time step_feedback.status_flags is 1
  (SWAYING) after something else (it starts "not swaying": the first SWAYING counts).
- The dynamic client sends, on every state, a WALK whose four slots are the steps
  next_step_index_needed .. +3 of the same circle, from next_step_index_needed even while
  it is 0 (before the walk: a slot with index 0 and the steps 1-3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tutorial_atlas_control.asi import Behavior
from tutorial_atlas_control.msgs.atlas_sim_interface import AsiCommand, ManipulateParams, StepData
from tutorial_atlas_control.msgs.atlas_sim_interface_state import AsiState

CIRCLE_R_M = 2.0
STEPS_PER_TURN = 60
STRIDE_WIDTH_M = 0.3
DURATION_S = 0.63
SWING_HEIGHT_M = 0.1
SWAYING = 1
#: A slot or desired step left empty.
EMPTY = StepData()


def circle_pose(counter: int, origin_xy: tuple[float, float]) -> tuple[float, float, float]:
    """The foot link's (x, y, yaw) of step `counter` (foot counter % 2)."""
    theta = counter * 2.0 * math.pi / STEPS_PER_TURN
    inside = counter % 2 == 0  # the left foot
    radius = CIRCLE_R_M - STRIDE_WIDTH_M / 2 if inside else CIRCLE_R_M + STRIDE_WIDTH_M / 2
    return (origin_xy[0] + radius * math.sin(theta),
            origin_xy[1] + CIRCLE_R_M - radius * math.cos(theta), theta)


def step_data(step_index: int, counter: int, origin_xy: tuple[float, float]) -> StepData:
    x, y, yaw = circle_pose(counter, origin_xy)
    return StepData(step_index, counter % 2, DURATION_S, (x, y, 0.0),
                    (0.0, 0.0, math.sin(0.5 * yaw), math.cos(0.5 * yaw)), SWING_HEIGHT_M)


def command(behavior: Behavior, queue: tuple[StepData, ...] = (EMPTY,) * 4,
            desired: StepData = EMPTY) -> AsiCommand:
    """The AtlasSimInterfaceCommand a client sends (no k_effort: the blend stays)."""
    return AsiCommand(0, int(behavior), queue, False, desired, False, ManipulateParams(),
                      None, 0)


@dataclass
class StaticCircleClient:
    """The tutorial's static mode."""

    counter: int = 0
    swaying: bool = False
    origin_xy: tuple[float, float] | None = None

    def desired_step(self, pelvis_xy: tuple[float, float], step_flags: int) -> StepData:
        """step_params.desired_step for a state with the pelvis at `pelvis_xy` (pos_est)
        and step_feedback.status_flags `step_flags`."""
        if self.origin_xy is None:
            self.origin_xy = pelvis_xy
        if step_flags == SWAYING and not self.swaying:
            self.counter += 1
            self.swaying = True
        elif step_flags != SWAYING:
            self.swaying = False
        return step_data(1, self.counter, self.origin_xy)

    def on_state(self, state: AsiState) -> AsiCommand:
        pelvis = (float(state.pelvis_position_m[0]), float(state.pelvis_position_m[1]))
        return command(Behavior.STEP,
                       desired=self.desired_step(pelvis, state.step_feedback.status_flags))


@dataclass
class DynamicCircleClient:
    """The tutorial's dynamic mode."""

    origin_xy: tuple[float, float] | None = None

    def step_queue(self, pelvis_xy: tuple[float, float],
                   next_step_index_needed: int) -> tuple[StepData, ...]:
        """walk_params.step_queue for a state with the pelvis at `pelvis_xy` and
        walk_feedback.next_step_index_needed."""
        if self.origin_xy is None:
            self.origin_xy = pelvis_xy
        first = next_step_index_needed
        return tuple(step_data(k, k, self.origin_xy) for k in range(first, first + 4))

    def on_state(self, state: AsiState) -> AsiCommand:
        pelvis = (float(state.pelvis_position_m[0]), float(state.pelvis_position_m[1]))
        return command(Behavior.WALK,
                       self.step_queue(pelvis, state.walk_feedback.next_step_index_needed))


def landing_errors(feet: np.ndarray, counter: int,
                   origin_xy: tuple[float, float]) -> tuple[float, float]:
    """How far foot counter % 2 (a foot_pos_est row: x, y, z, qx, qy, qz, qw) is from step
    `counter`'s pose: (m, rad)."""
    x, y, yaw = circle_pose(counter, origin_xy)
    foot = feet[counter % 2]
    qx, qy, qz, qw = (float(v) for v in foot[3:7])
    foot_yaw = math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))
    turn = (foot_yaw - yaw + math.pi) % (2.0 * math.pi) - math.pi
    return math.hypot(float(foot[0]) - x, float(foot[1]) - y), abs(turn)
