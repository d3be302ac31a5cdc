"""The smoothstep the timed moves follow, and its rate: the one blend of the controllers."""

from __future__ import annotations

import pytest

from tutorial_atlas_control.balance import smoothstep, smoothstep_rate


def test_smoothstep_is_held_outside_zero_to_one_and_half_way_at_its_middle() -> None:
    assert smoothstep(-0.5) == 0.0
    assert smoothstep(0.0) == 0.0
    assert smoothstep(0.5) == pytest.approx(0.5)
    assert smoothstep(1.0) == 1.0
    assert smoothstep(3.0) == 1.0


@pytest.mark.parametrize('fraction', [0.1, 0.37, 0.5, 0.9])
def test_the_rate_is_the_derivative_in_time(fraction: float) -> None:
    duration_s, dt = 2.0, 1e-6
    numeric = (smoothstep(fraction + dt / duration_s)
               - smoothstep(fraction - dt / duration_s)) / (2.0 * dt)
    assert smoothstep_rate(fraction, duration_s) == pytest.approx(numeric, rel=1e-6)


@pytest.mark.parametrize('fraction', [-0.2, 0.0, 1.0, 1.5])
def test_the_rate_is_zero_where_the_blend_is_held(fraction: float) -> None:
    assert smoothstep_rate(fraction, 1.0) == 0.0
