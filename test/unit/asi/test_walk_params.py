"""A WALK's queue as the soles' footsteps and walk_feedback back as the foot links' poses:
unused slots skipped, the sole's offset along each step's heading, four slots reported;
step_feedback alike, empty before the first step; an offline client's WALK of link poses."""

from __future__ import annotations

import math

import pytest

from tutorial_atlas_control.asi import Behavior
from tutorial_atlas_control.asi.walk_params import (
    footsteps_of,
    step_data_of,
    step_feedback,
    walk_command,
    walk_feedback,
)
from tutorial_atlas_control.msgs.atlas_sim_interface import StepData
from tutorial_atlas_control.walking import SWING_HEIGHT_M, Footstep, StepStatus, WalkStatus

AHEAD_M = 0.048


def test_a_foot_links_pose_becomes_its_soles_step_along_its_heading() -> None:
    yaw = math.pi / 2  # facing +y: the sole lies ahead in y
    queue = [StepData(), StepData(3, 1, 0.5, (1.0, 2.0, 0.3),
                                  (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)), 0.2)]
    (step,) = footsteps_of(queue, AHEAD_M)
    assert (step.step_index, step.foot_index, step.duration_s) == (3, 1, 0.5)
    assert step.x_m == pytest.approx(1.0) and step.y_m == pytest.approx(2.0 + AHEAD_M)
    assert step.yaw_rad == pytest.approx(yaw)


def test_feedback_gives_the_foot_links_back_in_four_slots() -> None:
    sole = Footstep(5, 0, 1.0 + AHEAD_M, 0.1, 0.0, 0.6)
    feedback = walk_feedback(WalkStatus(0.25, 4, 8, 2, (sole,)), AHEAD_M)
    assert (feedback.t_step_rem_s, feedback.current_step_index,
            feedback.next_step_index_needed, feedback.status_flags) == (0.25, 4, 8, 2)
    first, *rest = feedback.step_queue_saturated
    assert first == step_data_of(sole, AHEAD_M)
    assert first.position_m == pytest.approx((1.0, 0.1, 0.0))
    assert first.orientation_xyzw == (0.0, 0.0, 0.0, 1.0)
    assert first.swing_height_m == SWING_HEIGHT_M
    assert rest == [StepData()] * 3
    assert footsteps_of([first], AHEAD_M) == [sole]


def test_step_feedback_gives_the_step_as_clamped_as_its_foot_link() -> None:
    sole = Footstep(1, 1, 0.3 + AHEAD_M, -0.12, 0.0, 0.63)
    feedback = step_feedback(StepStatus(2, 0.4, 3, 4, sole), AHEAD_M)
    assert (feedback.status_flags, feedback.t_step_rem_s, feedback.current_step_index,
            feedback.next_step_index_needed) == (2, 0.4, 3, 4)
    assert feedback.desired_step_saturated == step_data_of(sole, AHEAD_M)
    assert feedback.desired_step_saturated.position_m == pytest.approx((0.3, -0.12, 0.0))
    assert step_feedback(StepStatus(1, 0.0, 0, 1, None), AHEAD_M).desired_step_saturated \
        == StepData()


def test_a_walk_command_carries_the_links_poses_in_four_slots() -> None:
    steps = [Footstep(7, 1, 1.0, -0.1, 0.0, 0.5), Footstep(8, 0, 1.2, 0.1, 0.0, 0.5)]
    command = walk_command(steps)
    assert command.behavior == Behavior.WALK
    assert [slot.step_index for slot in command.step_queue] == [7, 8, 0, 0]
    assert command.step_queue[1].position_m == (1.2, 0.1, 0.0)  # the link's, not moved
    assert footsteps_of(command.step_queue, 0.0) == steps


def test_a_walk_command_takes_at_most_four_steps() -> None:
    steps = [Footstep(k, k % 2, 0.1 * k, 0.0, 0.0) for k in range(1, 6)]
    with pytest.raises(ValueError, match='at most 4 steps, not 5'):
        walk_command(steps)
