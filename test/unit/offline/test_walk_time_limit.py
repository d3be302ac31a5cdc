"""A course walk gives each of its walks time for its steps and for its own sway and catch
(offline.walk_time_limit_s): a short look of steep steps is not given up on while the robot
catches itself at its end."""

from __future__ import annotations

import pytest

from tutorial_atlas_control.offline import WALK_OVERHEAD_S, walk_time_limit_s
from tutorial_atlas_control.walking import GroundGait, WalkGains


@pytest.mark.parametrize('steps', [1, 2, 4, 10, 95])
def test_a_walk_of_steep_steps_has_time_for_its_sway_steps_and_longest_catch(steps: int) -> None:
    gains = WalkGains()
    slowest = gains.sway_s + steps * GroundGait().steep_duration_s + gains.longest_catch_s
    assert walk_time_limit_s(steps) >= slowest


def test_the_overhead_is_the_walks_sway_and_longest_catch() -> None:
    gains = WalkGains()
    assert gains.sway_s + gains.longest_catch_s == pytest.approx(WALK_OVERHEAD_S)
    assert walk_time_limit_s(0) == pytest.approx(WALK_OVERHEAD_S)
    assert walk_time_limit_s(3) - walk_time_limit_s(2) == pytest.approx(0.9)
