"""The swing foot's path: at rest at both ends, lifted to its height at mid-swing, its
velocity and acceleration the rates of its position and velocity."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tutorial_atlas_control.walking.swing import SwingPath, bump, quintic

PATH = SwingPath(np.array([0.0, 0.12, 0.0]), np.array([0.4, 0.14, 0.02]), 0.0, 0.3, 0.6,
                 height_m=0.1)


@pytest.mark.parametrize('shape', [quintic, bump])
def test_the_shapes_derivatives_are_their_values_rates(shape) -> None:
    h = 1e-6
    for s in (0.1, 0.37, 0.5, 0.8):
        value, rate, acceleration = shape(s)
        assert rate == pytest.approx((shape(s + h)[0] - shape(s - h)[0]) / (2 * h), rel=1e-6,
                                     abs=1e-8)
        assert acceleration == pytest.approx((shape(s + h)[1] - shape(s - h)[1]) / (2 * h),
                                             rel=1e-5, abs=1e-6)
    assert quintic(0.0) == (0.0, 0.0, 0.0) and quintic(1.0)[:2] == (1.0, 0.0)
    assert bump(0.0) == (0.0, 0.0, 0.0) and bump(1.0) == (0.0, 0.0, 0.0)
    assert bump(0.5)[0] == 1.0


def test_the_foot_leaves_and_lands_at_rest_on_its_ends() -> None:
    for t, where, yaw in ((0.0, PATH.start, 0.0), (0.6, PATH.end, 0.3), (-1.0, PATH.start, 0.0),
                          (2.0, PATH.end, 0.3)):
        position, velocity, heading, turn_rate = PATH.at(t)
        assert position == pytest.approx(where, abs=1e-12)
        assert velocity == pytest.approx(np.zeros(3), abs=1e-12)
        assert (heading, turn_rate) == pytest.approx((yaw, 0.0), abs=1e-12)


def test_the_foot_is_highest_at_mid_swing_and_its_velocity_is_its_rate() -> None:
    position, velocity, _, turn_rate = PATH.at(0.3)
    assert position == pytest.approx([0.2, 0.13, 0.01 + 0.1])
    h = 1e-6
    for t in (0.1, 0.3, 0.45):
        rate = (PATH.at(t + h)[0] - PATH.at(t - h)[0]) / (2 * h)
        assert PATH.at(t)[1] == pytest.approx(rate, rel=1e-5)
        assert PATH.at(t)[3] == pytest.approx((PATH.at(t + h)[2] - PATH.at(t - h)[2]) / (2 * h))
    assert turn_rate == pytest.approx(0.3 * 1.875 / 0.6)


def test_the_acceleration_is_the_velocitys_rate_and_zero_at_rest() -> None:
    """The servo feeds it forward: without it the foot ran 2.5 cm ahead at touchdown."""
    h = 1e-6
    for t in (0.05, 0.2, 0.3, 0.52):
        acceleration, yaw_acceleration = PATH.acceleration(t)
        rate = (PATH.at(t + h)[1] - PATH.at(t - h)[1]) / (2 * h)
        assert acceleration == pytest.approx(rate, rel=1e-4, abs=1e-6)
        assert yaw_acceleration == pytest.approx(
            (PATH.at(t + h)[3] - PATH.at(t - h)[3]) / (2 * h), rel=1e-4, abs=1e-6)
    for t in (-0.1, 0.0, 0.6, 1.0):
        acceleration, yaw_acceleration = PATH.acceleration(t)
        assert not acceleration.any() and yaw_acceleration == 0.0


def test_the_turn_takes_the_short_way_round() -> None:
    # From 3.0 to -3.0 rad is 0.28 rad through pi, not 6 rad through 0.
    path = SwingPath(np.zeros(3), np.zeros(3), 3.0, -3.0, 1.0)
    assert abs(path.at(0.5)[2]) == pytest.approx(3.0 + (2 * math.pi - 6.0) / 2, abs=1e-12)


def test_a_swing_needs_a_positive_duration() -> None:
    with pytest.raises(ValueError, match='not positive'):
        SwingPath(np.zeros(3), np.ones(3), 0.0, 0.0, 0.0)
