"""A static step's swing over a cinder block (walking/step_over.py), without MuJoCo: toe and
heel clear the block's edge by the clearance wherever the sole is over the block and not yet
at its end, stepping up, down and across; the apex clears the highest of the ends and the
terrain; the ordinary swing is kept on flat ground; the path is at rest at its ends and its
velocity and acceleration are its rates; the sweep finds the block's top."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tutorial_atlas_control.walking.errors import WalkingError
from tutorial_atlas_control.walking.step_over import (
    STEP_OVER_CLEARANCE_M,
    StepOverPath,
    clear_apex_m,
    needs_step_over,
    sweep_points,
    terrain_top_m,
)

#: A cinder block lying across the path: its near and far edges along x (m), its top (m).
BLOCK_X = (0.2185, 0.4215)
BLOCK_TOP_M = 0.203
#: The sole's half length along x (m; Atlas's sole box).
HALF_LENGTH_M = 0.13
SOLE_HALF_SIZE_M = (0.13, 0.0624)


def block_height(x: float, y: float) -> float:
    """The ground: the floor at 0, the block's top over its extent (y: anywhere)."""
    del y
    return BLOCK_TOP_M if BLOCK_X[0] <= x <= BLOCK_X[1] else 0.0


def path_over_block(start_x: float, start_z: float, end_x: float, end_z: float,
                    duration_s: float = 1.5) -> StepOverPath:
    start, end = np.array([start_x, 0.12, start_z]), np.array([end_x, 0.12, end_z])
    points = sweep_points(start, end, 0.0, 0.0, SOLE_HALF_SIZE_M)
    apex = clear_apex_m(start_z, end_z, terrain_top_m(points, block_height))
    return StepOverPath(start, end, 0.0, 0.0, duration_s, apex)


CASES = {
    'onto': (0.016, 0.0, 0.32, BLOCK_TOP_M),
    'off the far side': (0.32, BLOCK_TOP_M, 0.61, 0.0),
    'back off': (0.32, BLOCK_TOP_M, 0.016, 0.0),
    'over, floor to floor': (-0.05, 0.0, 0.62, 0.0),
}


@pytest.mark.parametrize('case', CASES)
def test_toe_and_heel_clear_the_block_by_the_clearance_until_the_sole_is_over_its_end(
        case: str) -> None:
    """Wherever the sole's length (toe to heel) overlaps the block along the path, and the
    sole is neither where it lifted nor where it lands, its flat bottom is at least the
    clearance above the block's top: neither toe nor heel touches the edge."""
    start_x, start_z, end_x, end_z = CASES[case]
    path = path_over_block(start_x, start_z, end_x, end_z)
    lowest = math.inf
    for t in np.linspace(0.0, path.duration_s, 3001):
        position, _, _, _ = path.at(float(t))
        x = float(position[0])
        over_block = x + HALF_LENGTH_M > BLOCK_X[0] and x - HALF_LENGTH_M < BLOCK_X[1]
        moving = min(abs(x - start_x), abs(x - end_x)) > 1e-9
        if over_block and moving:
            lowest = min(lowest, float(position[2]) - BLOCK_TOP_M)
    assert lowest >= STEP_OVER_CLEARANCE_M - 1e-9, f'{case}: {lowest:.4f} m over the top'


def test_the_apex_clears_the_highest_of_the_ends_and_the_terrain() -> None:
    assert clear_apex_m(0.0, 0.203, 0.203) == pytest.approx(0.203 + STEP_OVER_CLEARANCE_M)
    assert clear_apex_m(0.203, 0.0, 0.203) == pytest.approx(0.203 + STEP_OVER_CLEARANCE_M)
    assert clear_apex_m(0.0, 0.0, 0.203, clearance_m=0.05) == pytest.approx(0.253)
    assert clear_apex_m(0.3, 0.1, 0.2) == pytest.approx(0.3 + STEP_OVER_CLEARANCE_M)


def test_flat_steps_keep_the_ordinary_swing() -> None:
    assert not needs_step_over(0.0, 0.0, 0.0)
    assert not needs_step_over(0.0, 0.01, 0.015)  # the ordinary swing's 8 cm bump clears it
    assert needs_step_over(0.0, 0.203, 0.203)
    assert needs_step_over(0.203, 0.0, 0.203)
    assert needs_step_over(0.0, 0.0, 0.203)


def test_the_path_leaves_and_lands_at_rest_and_turns_while_across() -> None:
    path = StepOverPath(np.array([0.0, 0.1, 0.0]), np.array([0.3, 0.12, 0.2]), 0.0, 0.2, 1.5,
                        0.26)
    for t, where, yaw in ((0.0, path.start, 0.0), (1.5, path.end, 0.2),
                          (-1.0, path.start, 0.0), (3.0, path.end, 0.2)):
        position, velocity, heading, turn_rate = path.at(t)
        assert position == pytest.approx(where, abs=1e-12)
        assert velocity == pytest.approx(np.zeros(3), abs=1e-12)
        assert (heading, turn_rate) == pytest.approx((yaw, 0.0), abs=1e-12)
    position, _, heading, _ = path.at(0.75)
    assert position == pytest.approx([0.15, 0.11, 0.26])
    assert heading == pytest.approx(0.1)
    assert path.descent_s == pytest.approx(1.0)


def test_the_velocity_and_acceleration_are_the_rates_and_continuous_at_the_corners() -> None:
    path = StepOverPath(np.array([0.0, 0.1, 0.0]), np.array([0.3, 0.12, 0.2]), 0.0, 0.2, 1.5,
                        0.26)
    h = 1e-6
    for t in (0.1, 0.3, 0.499, 0.501, 0.75, 1.1, 1.4):
        assert path.at(t)[1] == pytest.approx(
            (path.at(t + h)[0] - path.at(t - h)[0]) / (2 * h), rel=1e-5, abs=1e-7)
        acceleration, yaw_acceleration = path.acceleration(t)
        assert acceleration == pytest.approx(
            (path.at(t + h)[1] - path.at(t - h)[1]) / (2 * h), rel=1e-4, abs=1e-5)
        assert yaw_acceleration == pytest.approx(
            (path.at(t + h)[3] - path.at(t - h)[3]) / (2 * h), rel=1e-4, abs=1e-5)
    for corner in (0.5, 1.0):  # at rest between one move and the next
        assert path.acceleration(corner - 1e-9)[0] == pytest.approx(
            path.acceleration(corner + 1e-9)[0], abs=1e-6)


def test_an_apex_below_an_end_or_no_duration_is_refused() -> None:
    with pytest.raises(WalkingError, match='apex 0.1 m is below an end'):
        StepOverPath(np.zeros(3), np.array([0.3, 0.0, 0.2]), 0.0, 0.0, 1.5, 0.1)
    with pytest.raises(WalkingError, match='duration 0.0 s is not positive'):
        StepOverPath(np.zeros(3), np.array([0.3, 0.0, 0.2]), 0.0, 0.0, 0.0, 0.3)


def test_the_sweep_finds_the_block_under_the_sole_on_its_way_and_not_beside_it() -> None:
    onto = sweep_points(np.array([0.016, 0.12]), np.array([0.32, 0.12]), 0.0, 0.0,
                        SOLE_HALF_SIZE_M)
    assert terrain_top_m(onto, block_height) == BLOCK_TOP_M
    # The toe stops 4 cm short of the edge: no block under the sweep.
    short = sweep_points(np.array([0.0, 0.12]), np.array([0.0485, 0.12]), 0.0, 0.0,
                         SOLE_HALF_SIZE_M)
    assert terrain_top_m(short, block_height) == 0.0
    assert terrain_top_m(short, lambda x, y: -math.inf) == -math.inf
