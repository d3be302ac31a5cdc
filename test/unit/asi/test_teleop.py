"""The keyboard teleop's keys and the ego-centric steps each asks for."""

from __future__ import annotations

import math

import pytest

from tutorial_atlas_control.asi.teleop import MOVES, Settings, ego_steps, key_action
from tutorial_atlas_control.walking import LEFT, RIGHT


def test_keys_walk_step_set_and_quit() -> None:
    settings = Settings()
    assert key_action('i', settings) == ('walk', 'forward')
    assert key_action('<', settings) == ('step', 'back')
    assert key_action('7', settings) == ('settings', Settings(7, 0.2))
    assert key_action('=', Settings(4, 0.40)) == ('settings', Settings(4, 0.40))  # at most
    assert key_action('-', Settings(4, 0.05)) == ('settings', Settings(4, 0.05))  # at least
    assert key_action('-', settings) == ('settings', Settings(4, 0.15))
    assert [key_action(k, settings)[0] for k in 'RSHQx'] == ['stand up', 'stand', 'harness',
                                                           'quit', 'unknown']


@pytest.mark.parametrize('move', sorted(MOVES.values()))
def test_every_move_numbers_its_steps_and_alternates_its_feet(move: str) -> None:
    steps = ego_steps(move, Settings(5, 0.2))
    assert [s.step_index for s in steps] == [1, 2, 3, 4, 5]
    assert all(a.foot_index != b.foot_index for a, b in zip(steps, steps[1:]))


def test_forward_back_and_the_side_steps_end_with_the_feet_side_by_side() -> None:
    forward = ego_steps('forward', Settings(4, 0.25))
    assert [s.x_m for s in forward] == pytest.approx([0.25, 0.5, 0.75, 0.75])
    assert [s.x_m for s in ego_steps('back', Settings(2, 0.25))] == pytest.approx([-0.25, -0.25])
    side = ego_steps('side left', Settings(4, 0.2))
    assert [(s.foot_index, round(s.y_m, 3)) for s in side] == [
        (LEFT, 0.22), (RIGHT, -0.02), (LEFT, 0.32), (RIGHT, 0.08)]


def test_turns_lead_with_the_foot_turned_to_and_turn_each_step() -> None:
    left = ego_steps('turn left', Settings(2, 0.2))
    assert left[0].foot_index == LEFT and left[1].yaw_rad == pytest.approx(0.2)
    # Each foot stays 0.12 m from the pelvis, across its heading.
    assert all(math.hypot(s.x_m, s.y_m) == pytest.approx(0.12) for s in left)
    right = ego_steps('turn right', Settings(2, 0.2))
    assert right[0].foot_index == RIGHT and right[1].yaw_rad == pytest.approx(-0.2)


def test_a_curve_right_is_a_curve_left_mirrored() -> None:
    left, right = (ego_steps(m, Settings(4, 0.2)) for m in ('curve left', 'curve right'))
    for a, b in zip(left, right):
        assert (b.foot_index, b.x_m, b.y_m, b.yaw_rad) == pytest.approx(
            (1 - a.foot_index, a.x_m, -a.y_m, -a.yaw_rad))
    assert 0.0 < left[-1].yaw_rad < 0.5
