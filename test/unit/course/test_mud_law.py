"""course.mud: DRCSim's MudPlugin drag as a law, against its formula."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tutorial_atlas_control.course import (
    MUD_DAMPING,
    MUD_DAMPING_FINALS,
    CourseError,
    check_mud_damping,
    drag_at_point,
    drag_wrench,
    implicit_drag,
    wrench_at_com,
)


def test_drag_wrench_is_the_formula_by_hand() -> None:
    # F = -40 v; torque = -40 w + (p - com) x F, with the arm (0, 0, 0.5).
    wrench = drag_wrench(40.0, np.array([0.1, -0.2, 0.3]), np.array([1.0, 0.0, -2.0]),
                         np.array([1.0, 2.0, 3.0]), np.array([1.0, 2.0, 2.5]))
    np.testing.assert_allclose(wrench, [-4.0, 8.0, -12.0, -44.0, -2.0, 80.0], atol=1e-12)


def test_the_wrench_at_the_com_has_the_points_moment() -> None:
    rng = np.random.default_rng(3)
    at_point = rng.normal(size=(4, 6))
    points, coms = rng.normal(size=(4, 3)), rng.normal(size=(4, 3))
    at_com = wrench_at_com(at_point, points, coms)
    np.testing.assert_array_equal(at_com[:, 0:3], at_point[:, 0:3])
    # About the point, the moved wrench's moment is the original torque again.
    back = at_com[:, 3:6] + np.cross(coms - points, at_com[:, 0:3])
    np.testing.assert_allclose(back, at_point[:, 3:6], atol=1e-12)


def test_implicit_drag_is_minus_c_times_the_twist_it_leaves() -> None:
    rng = np.random.default_rng(5)
    half = rng.normal(size=(12, 12))
    mobility = half @ half.T  # J M^-1 J^T: symmetric, positive
    twists = rng.normal(size=(2, 6))
    wrench = implicit_drag(MUD_DAMPING, 1e-3, twists, mobility)
    twist_after = twists.reshape(-1) + 1e-3 * mobility @ wrench.reshape(-1)
    np.testing.assert_allclose(wrench.reshape(-1), -MUD_DAMPING * twist_after, atol=1e-10)
    # With a vanishing step it is the explicit law.
    np.testing.assert_allclose(implicit_drag(MUD_DAMPING, 1e-12, twists, mobility),
                               drag_at_point(MUD_DAMPING, twists), rtol=1e-6)


@pytest.mark.parametrize('damping', [MUD_DAMPING, MUD_DAMPING_FINALS])
def test_a_foot_turning_in_mud_slows_down_implicitly_where_explicitly_it_blows_up(
        damping: float) -> None:
    # Atlas's foot about its ankle roll: about 0.0093 kg m^2; 1 ms steps.
    inertia, dt_s = 0.0093, 1e-3
    implicit, explicit = 1.0, 1.0
    for _ in range(20):
        torque = implicit_drag(damping, dt_s, np.array([0, 0, 0, implicit, 0, 0]),
                               np.diag([1.0, 1.0, 1.0, 1.0 / inertia, 1.0, 1.0]))[0, 3]
        implicit += dt_s * torque / inertia
        explicit += dt_s * drag_at_point(damping, np.array([explicit]))[0] / inertia
    assert 0.0 < implicit < 1e-3
    assert abs(explicit) > 1e6


@pytest.mark.parametrize('good', [0, 0.0, 40, 70.0])
def test_a_damping_of_zero_or_more_is_taken(good: float) -> None:
    assert check_mud_damping(good) == float(good)


@pytest.mark.parametrize('bad, reason', [
    (-1.0, r'>= 0'), (math.nan, r'finite'), (math.inf, r'finite'), ('40', r'number'),
    (True, r'number'), (None, r'number'), (1e9, r'exceeds'),
])
def test_a_bad_damping_is_one_line_naming_it(bad: object, reason: str) -> None:
    with pytest.raises(CourseError, match=reason) as raised:
        check_mud_damping(bad, '~mud_damping')
    assert str(raised.value).startswith('~mud_damping') and '\n' not in str(raised.value)
