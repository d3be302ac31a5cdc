"""Walk's queue: merging by index, re-requests, clamping, the feedback flags."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from tutorial_atlas_control.walking.footsteps import (
    DRCSIM_WALK_QUEUE,
    LEFT,
    RIGHT,
    Footstep,
    straight_steps,
    window,
)
from tutorial_atlas_control.walking.status_flags import (
    ERROR_INCONSISTENT_STEPS,
    STEPPING,
    SWAYING,
    WARNING_INSUFFICIENT_STEP_DATA,
)
from tutorial_atlas_control.walking.step_queue import (
    StepLimits,
    StepQueue,
    clamp_step,
)

START_LEFT = Footstep(0, LEFT, 0.0, 0.12, 0.0)
START_RIGHT = Footstep(0, RIGHT, 0.0, -0.12, 0.0)


def new_queue() -> StepQueue:
    return StepQueue(START_LEFT, START_RIGHT)


def test_re_sending_the_same_window_changes_nothing() -> None:
    queue = new_queue()
    queue.offer(DRCSIM_WALK_QUEUE)
    first = queue.preview()
    for _ in range(1000):
        queue.offer(DRCSIM_WALK_QUEUE)
    assert queue.preview() == first == list(DRCSIM_WALK_QUEUE)
    assert queue.status_flags(SWAYING) == SWAYING


def test_a_streaming_client_keeps_the_queue_full_to_the_end() -> None:
    plan = straight_steps(10, 0.25)
    queue = new_queue()
    assert queue.next_step_index_needed == 1
    taken = []
    while queue.current_step_index < len(plan):
        # What a client streaming the window [next_step_index_needed, +3] keeps sending.
        for _ in range(3):
            queue.offer(window(plan, queue.next_step_index_needed))
        preview = queue.preview()
        remaining = len(plan) - queue.current_step_index
        assert len(preview) == min(4, remaining)
        flags = queue.status_flags(STEPPING)
        assert bool(flags & WARNING_INSUFFICIENT_STEP_DATA) == (remaining < 4)
        queue.touchdown(preview[0])
        taken.append(preview[0])
    assert taken == plan
    assert queue.next_step_index_needed == 11


def test_next_step_index_needed_is_the_first_unknown_step_up_to_four_ahead() -> None:
    queue = new_queue()
    queue.offer(DRCSIM_WALK_QUEUE[:2])
    assert queue.next_step_index_needed == 3
    queue.offer(DRCSIM_WALK_QUEUE)
    assert queue.next_step_index_needed == 4
    queue.touchdown(DRCSIM_WALK_QUEUE[0])
    assert queue.next_step_index_needed == 5


def test_a_one_shot_queue_runs_out_and_says_so() -> None:
    queue = new_queue()
    queue.offer(DRCSIM_WALK_QUEUE)
    queue.touchdown(queue.preview()[0])
    assert [s.step_index for s in queue.preview()] == [2, 3, 4]
    assert queue.status_flags(STEPPING) == STEPPING | WARNING_INSUFFICIENT_STEP_DATA
    for _ in range(3):
        queue.touchdown(queue.preview()[0])
    assert queue.preview() == []


def test_a_later_copy_of_an_index_replaces_it_and_taken_steps_are_ignored() -> None:
    queue = new_queue()
    queue.offer(DRCSIM_WALK_QUEUE)
    queue.touchdown(DRCSIM_WALK_QUEUE[0])
    moved = replace(DRCSIM_WALK_QUEUE[1], x_m=0.35)
    queue.offer([replace(DRCSIM_WALK_QUEUE[0], x_m=9.0), moved])
    assert queue.preview()[0] == moved


def test_two_steps_with_the_same_foot_are_inconsistent_and_latched() -> None:
    queue = new_queue()
    queue.offer([DRCSIM_WALK_QUEUE[0], replace(DRCSIM_WALK_QUEUE[1], foot_index=LEFT)])
    assert len(queue.preview()) == 1
    assert queue.status_flags(SWAYING) & ERROR_INCONSISTENT_STEPS
    queue.offer(DRCSIM_WALK_QUEUE)
    assert queue.status_flags(SWAYING) & ERROR_INCONSISTENT_STEPS


@pytest.mark.parametrize('target, expected', [
    ((1.0, 0.2, 0.0), (0.40, 0.2, 0.0)),      # too far ahead: the stride limit
    ((-0.5, 0.2, 0.0), (-0.20, 0.2, 0.0)),    # too far back
    ((0.1, 0.02, 0.0), (0.1, 0.16, 0.0)),     # too narrow: the minimum width
    ((0.1, -0.3, 0.0), (0.1, 0.16, 0.0)),     # across the stance foot: back to its side
    ((0.1, 0.2, 1.0), (0.1, 0.2, 0.40)),      # too sharp a turn
])
def test_clamp_step_in_the_stance_foots_frame(target: tuple, expected: tuple) -> None:
    stance = Footstep(0, RIGHT, 0.0, 0.0, 0.0)
    step = clamp_step(Footstep(1, LEFT, *target), stance, StepLimits())
    assert (step.x_m, step.y_m, step.yaw_rad) == pytest.approx(expected)


def test_clamp_step_turns_with_the_stance_foot() -> None:
    stance = Footstep(0, RIGHT, 1.0, 1.0, math.pi / 2)
    # 1 m ahead along the stance foot's heading (+y) is clamped to 0.4 m; left is -x.
    step = clamp_step(Footstep(1, LEFT, 0.8, 2.0, math.pi / 2), stance)
    assert (step.x_m, step.y_m, step.yaw_rad) == pytest.approx((0.8, 1.4, math.pi / 2))


def test_within_one_command_the_first_copy_of_an_index_counts() -> None:
    """DRCSim's actionlib server pads a two-step walk to [1, 2, 2, 3] with copies of the
    steps two before: the walk takes 1, 2, then 3 (a copy of 2, the same foot: it ends)."""
    first, second = Footstep(1, LEFT, 0.2, 0.12, 0.0), Footstep(2, RIGHT, 0.4, -0.12, 0.0)
    queue = StepQueue(Footstep(0, LEFT, 0.0, 0.12, 0.0), Footstep(0, RIGHT, 0.0, -0.12, 0.0))
    queue.offer([first, second, replace(first, step_index=2), replace(second, step_index=3)])
    assert [step.step_index for step in queue.preview()] == [1, 2]
    assert queue.preview()[1].foot_index == RIGHT and queue.inconsistent


def test_an_adjusted_step_is_what_the_preview_reports_until_it_is_down() -> None:
    queue = new_queue()
    queue.offer(DRCSIM_WALK_QUEUE)
    moved = replace(DRCSIM_WALK_QUEUE[0], y_m=0.35)
    queue.adjust(moved)
    preview = queue.preview()
    assert preview[0] == moved
    # The next step is clamped from where the adjusted one lands: 0.40 m across at most.
    assert preview[1].y_m == pytest.approx(0.35 - 0.40)
    # A client re-sending the step under way does not undo the adjustment.
    queue.offer(DRCSIM_WALK_QUEUE)
    assert queue.preview()[0] == moved
    queue.touchdown(moved)
    assert queue.feet[LEFT] == moved
    assert queue.preview()[0] == preview[1]


def test_only_the_step_under_way_is_adjusted() -> None:
    queue = new_queue()
    queue.offer(DRCSIM_WALK_QUEUE)
    with pytest.raises(ValueError, match='step 2 is not the one under way \\(1\\)'):
        queue.adjust(DRCSIM_WALK_QUEUE[1])


def test_stopped_the_preview_ends_with_the_step_under_way() -> None:
    queue = new_queue()
    queue.offer(DRCSIM_WALK_QUEUE)
    assert len(queue.preview()) == 4
    queue.stop(1)
    assert queue.preview() == [DRCSIM_WALK_QUEUE[0]]
    queue.offer(DRCSIM_WALK_QUEUE)  # ignored once stopped
    assert queue.preview() == [DRCSIM_WALK_QUEUE[0]]
