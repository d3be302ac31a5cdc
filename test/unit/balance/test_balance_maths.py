"""The balance's pure pieces against analytic cases: the LIPM and its capture point, the
support polygon, and the split of a wrench between the feet."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tutorial_atlas_control.balance import BalanceError, contact_wrench, lipm, support
from tutorial_atlas_control.errors import AtlasControlError

OMEGA = lipm.natural_frequency(0.9)


def test_natural_frequency_is_sqrt_g_over_z() -> None:
    assert pytest.approx(math.sqrt(9.81 / 0.9)) == OMEGA
    with pytest.raises(ValueError, match='centre-of-mass height 0.0 m must be above'):
        lipm.natural_frequency(0.0)


def test_a_pendulum_under_the_ground_raises_the_balances_error() -> None:
    with pytest.raises(BalanceError, match='height -0.1 m must be above the ground') as raised:
        lipm.natural_frequency(-0.1)
    assert isinstance(raised.value, AtlasControlError)  # what the command lines catch


def test_the_lipm_solution_obeys_its_equation() -> None:
    """c'' = omega^2 (c - p): the closed form against a central difference."""
    c0, v0, p = np.array([0.03, -0.01]), np.array([0.2, 0.1]), np.array([0.05, 0.0])
    h = 1e-4
    before, _ = lipm.lipm_state(c0, v0, p, OMEGA, 0.5 - h)
    now, velocity = lipm.lipm_state(c0, v0, p, OMEGA, 0.5)
    after, _ = lipm.lipm_state(c0, v0, p, OMEGA, 0.5 + h)
    np.testing.assert_allclose((after - 2 * now + before) / h**2,
                               lipm.com_acceleration(now, p, OMEGA), rtol=1e-5)
    np.testing.assert_allclose((after - before) / (2 * h), velocity, rtol=1e-6)


def test_a_pressure_centre_on_the_capture_point_brings_the_pendulum_to_rest() -> None:
    c0, v0 = np.array([0.0, 0.0]), np.array([0.3, -0.2])
    xi = lipm.capture_point(c0, v0, OMEGA)
    np.testing.assert_allclose(xi, c0 + v0 / OMEGA)
    com, velocity = lipm.lipm_state(c0, v0, xi, OMEGA, 3.0)
    np.testing.assert_allclose(com, xi, atol=2e-5)
    np.testing.assert_allclose(velocity, 0.0, atol=2e-4)
    # Anywhere else, the pendulum runs away from the pressure centre.
    com, _ = lipm.lipm_state(c0, v0, xi - [0.01, 0.0], OMEGA, 3.0)
    assert com[0] > xi[0] + 1.0


@pytest.mark.parametrize('t_s', [0.0, 0.3, 0.9])
def test_the_capture_points_motion_is_the_pendulums(t_s: float) -> None:
    """capture_point_after is xi = c + c'/omega of the exact LIPM state (cosh, sinh)."""
    c0, v0, cop = np.array([0.03, -0.02]), np.array([0.15, 0.05]), np.array([0.01, 0.02])
    com, velocity = lipm.lipm_state(c0, v0, cop, OMEGA, t_s)
    xi0 = lipm.capture_point(c0, v0, OMEGA)
    np.testing.assert_allclose(lipm.capture_point_after(xi0, cop, OMEGA, t_s),
                               lipm.capture_point(com, velocity, OMEGA), atol=1e-12)
    # Run back by as long, it returns where it started; one axis as plain floats.
    ahead = lipm.capture_point_after(xi0, cop, OMEGA, t_s)
    np.testing.assert_allclose(lipm.capture_point_after(ahead, cop, OMEGA, -t_s), xi0,
                               atol=1e-12)
    assert lipm.capture_point_after(0.04, 0.01, OMEGA, t_s) == pytest.approx(
        0.01 + 0.03 * math.exp(OMEGA * t_s))


def test_the_pressure_centre_reaching_a_target_takes_the_capture_point_there() -> None:
    duration = 0.6
    start, target = np.array([0.02, 0.0]), np.array([0.05, -0.08])
    cop = lipm.cop_reaching(start, target, OMEGA, duration)
    end = cop + (start - cop) * math.exp(OMEGA * duration)  # the closed form
    np.testing.assert_allclose(end, target, atol=1e-12)
    # It lies behind the start, away from the target: it pushes the capture point there.
    assert np.dot(cop - start, target - start) < 0.0


@pytest.mark.parametrize('gain', [0.0, 0.5, 2.0])
def test_the_capture_point_law_makes_its_error_decay_at_omega_gain(gain: float) -> None:
    """xi' = omega (xi - p) with p = xi + k (xi - xi_ref): the error is e^(-omega k t)."""
    xi_ref, xi, dt = np.array([0.02, 0.0]), np.array([0.10, -0.04]), 1e-4
    for _ in range(int(0.5 / dt)):
        xi = xi + dt * OMEGA * (xi - lipm.dcm_feedback_cop(xi, xi_ref, gain))
    expected = np.array([0.08, -0.04]) * math.exp(-OMEGA * gain * 0.5)
    np.testing.assert_allclose(xi - xi_ref, expected, rtol=5e-3)  # Euler's error


SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def test_the_hull_drops_interior_and_collinear_points_counter_clockwise() -> None:
    points = np.vstack([SQUARE[::-1], [[0.5, 0.5], [0.5, 0.0], [0.2, 0.7]]])
    hull = support.convex_hull(points)
    np.testing.assert_array_equal(hull, SQUARE)
    assert support.signed_distance(hull, [0.5, 0.25]) == pytest.approx(0.25)
    assert support.signed_distance(hull, [1.5, 0.5]) == pytest.approx(-0.5)
    assert support.inside(hull, [0.5, 0.5], 0.4) and not support.inside(hull, [0.5, 0.5], 0.6)


def test_clamping_keeps_a_point_inside_and_projects_one_outside() -> None:
    np.testing.assert_array_equal(support.clamp_into(SQUARE, [0.5, 0.5], 0.1), [0.5, 0.5])
    np.testing.assert_allclose(support.clamp_into(SQUARE, [2.0, 0.5], 0.1), [0.9, 0.5])
    np.testing.assert_allclose(support.clamp_into(SQUARE, [2.0, 2.0], 0.1), [0.9, 0.9])
    np.testing.assert_allclose(support.clamp_into(SQUARE, [0.5, -3.0]), [0.5, 0.0])
    np.testing.assert_allclose(support.shrink(SQUARE, 0.25),
                               [[0.25, 0.25], [0.75, 0.25], [0.75, 0.75], [0.25, 0.75]])
    # A margin that swallows the polygon leaves its centroid.
    np.testing.assert_allclose(support.clamp_into(SQUARE, [3.0, 0.0], 0.6), [0.5, 0.5])


FEET = np.array([[0.0, 0.1, 0.0], [0.0, -0.1, 0.0]])
COM = np.array([0.0, 0.0, 0.9])


def resultant(wrenches: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    force = wrenches[:, 0:3].sum(axis=0)
    moment = sum(np.cross(FEET[i] - COM, wrenches[i, 0:3]) + wrenches[i, 3:6] for i in (0, 1))
    return force, moment


def test_the_split_sums_to_the_wrench_and_shares_the_weight_evenly() -> None:
    weight = np.array([0.0, 0.0, 900.0])
    wrenches = contact_wrench.split_wrench(weight, np.zeros(3), FEET, COM, (True, True))
    np.testing.assert_allclose(wrenches[:, 2], [450.0, 450.0])
    np.testing.assert_allclose(wrenches[:, 3:6], 0.0, atol=1e-9)


def test_a_roll_moment_is_made_by_shifting_load_not_by_the_ankles() -> None:
    """Moment about x of +45 N m: all of it by the left foot (y = +0.1) taking 450 N
    more, none at the ankles; beyond, the lighter foot keeps MIN_LOAD_SHARE of the load and
    the ankles make the rest."""
    force, moment = np.array([10.0, 0.0, 900.0]), np.array([45.0, 3.0, 2.0])
    wrenches = contact_wrench.split_wrench(force, moment, FEET, COM, (True, True))
    got_force, got_moment = resultant(wrenches)
    np.testing.assert_allclose(got_force, force, atol=1e-9)
    np.testing.assert_allclose(got_moment, moment, atol=1e-9)
    assert wrenches[0, 2] - wrenches[1, 2] == pytest.approx(450.0)
    np.testing.assert_allclose(wrenches[:, 3], 0.0, atol=1e-9)
    beyond = contact_wrench.split_wrench(force, moment * 3, FEET, COM, (True, True))
    share = contact_wrench.MIN_LOAD_SHARE
    np.testing.assert_allclose(beyond[:, 0:3], [[(1 - share) * f for f in force],
                                                [share * f for f in force]])
    np.testing.assert_allclose(resultant(beyond)[1], moment * 3, atol=1e-9)


def test_one_foot_takes_everything_and_a_lifted_one_nothing() -> None:
    force, moment = np.array([0.0, 0.0, 900.0]), np.zeros(3)
    wrenches = contact_wrench.split_wrench(force, moment, FEET, COM, (False, True))
    np.testing.assert_array_equal(wrenches[0], 0.0)
    got_force, got_moment = resultant(wrenches)
    np.testing.assert_allclose(got_force, force, atol=1e-9)
    np.testing.assert_allclose(got_moment, moment, atol=1e-9)


def test_feasibility_keeps_the_pressure_centre_on_the_sole_and_no_pull() -> None:
    rotation = np.eye(3)
    feasible = contact_wrench.make_feasible(np.array([0, 0, 400.0, 50.0, -80.0, 3.0]),
                                            rotation, 0.13, 0.06)
    np.testing.assert_allclose(feasible, [0, 0, 400.0, 24.0, -52.0, 3.0])
    pulled = contact_wrench.make_feasible(np.array([5.0, 0, -10.0, 1.0, 1.0, 0.0]),
                                          rotation, 0.13, 0.06)
    np.testing.assert_allclose(pulled, [5.0, 0, 0, 0, 0, 0])


def test_feasibility_keeps_the_pressure_centre_on_a_rectangle_off_the_soles_centre() -> None:
    """A rectangle 4 cm by 1 cm about (0.09, 0.05) of a sole heading +y: a pressure
    centre asked at the sole's centre comes to its nearest corner; one inside it stays."""
    turned = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # heading +y
    centred = contact_wrench.make_feasible(np.array([0, 0, 500.0, 0, 0, 0]), turned, 0.02,
                                           0.005, centre_m=(0.09, 0.05))
    # the sole's (along, across) (0.07, 0.045) is the world's (-0.045, 0.07): m = r x f
    np.testing.assert_allclose(centred, [0, 0, 500.0, 0.07 * 500.0, 0.045 * 500.0, 0],
                               atol=1e-9)
    inside = np.array([0, 0, 500.0, 0.1 * 500.0, 0.05 * 500.0, 0])  # at (0.1, 0.05)
    np.testing.assert_allclose(contact_wrench.make_feasible(
        inside, turned, 0.02, 0.005, centre_m=(0.09, 0.05)), inside, atol=1e-9)
