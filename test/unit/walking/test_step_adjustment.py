"""Step adjustment: the capture point's error predicted at touchdown under the clamped law,
and the foothold that carries it into the next step's plan."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tutorial_atlas_control.balance.lipm import natural_frequency
from tutorial_atlas_control.walking.dcm_plan import DcmPlan
from tutorial_atlas_control.walking.step_adjustment import foothold_shift, predicted_error

OMEGA = natural_frequency(0.8)
GAIN = 1.5
#: The pressure centre's reach from the sole's centre: along it, across it (m).
REACH = (0.115, 0.047)
STRAIGHT = (1.0, 0.0)


def integrated(error_m: float, reach_m: float, remaining_s: float, dt: float = 1e-5) -> float:
    """The clamped law e' = omega (e - clamp((1 + k) e, +-reach)), integrated (Euler)."""
    error = error_m
    for _ in range(round(remaining_s / dt)):
        cop = min(max((1.0 + GAIN) * error, -reach_m), reach_m)
        error += dt * OMEGA * (error - cop)
    return error


@pytest.mark.parametrize('error_m', [0.005, -0.015, 0.025, -0.04, 0.046, 0.06, -0.1])
@pytest.mark.parametrize('remaining_s', [0.05, 0.3, 0.6])
def test_the_prediction_is_the_clamped_laws_solution(error_m: float,
                                                     remaining_s: float) -> None:
    # Unsaturated (|e| <= 0.0188), saturated and coming back, at the edge, beyond it.
    expected = integrated(error_m, REACH[1], remaining_s)
    assert predicted_error(error_m, REACH[1], GAIN, OMEGA, remaining_s) == pytest.approx(
        expected, rel=2e-3, abs=1e-6)


def test_the_prediction_is_continuous_where_the_law_saturates_and_at_the_edge() -> None:
    reach = REACH[1]
    for boundary in (reach / (1.0 + GAIN), reach):
        below = predicted_error(boundary - 1e-9, reach, GAIN, OMEGA, 0.4)
        above = predicted_error(boundary + 1e-9, reach, GAIN, OMEGA, 0.4)
        assert above == pytest.approx(below, abs=1e-7)


def test_with_no_time_left_the_error_is_what_it_is() -> None:
    assert predicted_error(0.3, REACH[1], GAIN, OMEGA, 0.0) == 0.3
    assert predicted_error(-0.01, REACH[1], GAIN, OMEGA, -0.1) == -0.01


def test_an_error_the_sole_takes_back_barely_moves_the_foot() -> None:
    shift = foothold_shift((0.0, 0.015), STRAIGHT, (0.0, 0.0), REACH, GAIN, OMEGA, 0.5, 0.63)
    assert np.hypot(*shift) < 0.015 * math.exp(-GAIN * OMEGA * 0.5) * 1.2


def test_an_error_past_the_soles_edge_moves_the_foot_by_its_prediction_carried() -> None:
    error, remaining, after = 0.06, 0.4, 0.63
    shift = foothold_shift((0.0, error), STRAIGHT, (0.0, 0.0), REACH, GAIN, OMEGA, remaining,
                           after)
    at_touchdown = REACH[1] + (error - REACH[1]) * math.exp(OMEGA * remaining)
    carried = 1.0 / (1.0 - math.exp(-OMEGA * after))
    assert shift == pytest.approx((0.0, at_touchdown * carried), abs=1e-12)
    # The last step before the catch carries nothing: both feet take the error.
    last = foothold_shift((0.0, error), STRAIGHT, (0.0, 0.0), REACH, GAIN, OMEGA, remaining,
                          None)
    assert last == pytest.approx((0.0, at_touchdown), abs=1e-12)


def test_the_shifted_foothold_puts_the_next_steps_plan_where_the_capture_point_lands() -> None:
    # The next steps' pressure centres; the error at touchdown, and the foothold moved for
    # it: the replanned capture point at the next step's start moves by that error.
    cops = np.array([[0.25, 0.12], [0.5, -0.12], [0.75, 0.12]])
    durations = np.full(3, 0.63)
    final = np.array([0.75, 0.0])
    shift = np.array(foothold_shift((0.02, -0.07), STRAIGHT, (0.0, 0.0), REACH, GAIN, OMEGA,
                                    0.3, durations[0]))
    at_touchdown = np.array([predicted_error(0.02, REACH[0], GAIN, OMEGA, 0.3),
                             predicted_error(-0.07, REACH[1], GAIN, OMEGA, 0.3)])
    moved = cops.copy()
    moved[0] += shift
    before = DcmPlan.plan(cops, durations, final, OMEGA).start
    after = DcmPlan.plan(moved, durations, final, OMEGA).start
    assert after - before == pytest.approx(at_touchdown, abs=1e-12)


def test_the_soles_frame_decides_which_reach_applies() -> None:
    # 6 cm across a straight sole is past its edge; along a sole turned a quarter turn, it is
    # within its length and the law takes it back.
    error = (0.0, 0.06)
    straight = foothold_shift(error, STRAIGHT, (0.0, 0.0), REACH, GAIN, OMEGA, 0.4, 0.63)
    turned = foothold_shift(error, (0.0, 1.0), (0.0, 0.0), REACH, GAIN, OMEGA, 0.4, 0.63)
    assert straight[1] > 0.1 and abs(straight[0]) < 1e-12
    assert abs(turned[0]) < 1e-12 and 0.0 < turned[1] < 0.01


def test_a_plan_pressure_centre_off_the_soles_centre_has_less_room_on_that_side() -> None:
    # The plan's pressure centre 1 cm towards the error: 1 cm less room to the edge.
    error = (0.0, 0.04)
    centred = foothold_shift(error, STRAIGHT, (0.0, 0.0), REACH, GAIN, OMEGA, 0.4, None)
    towards = foothold_shift(error, STRAIGHT, (0.0, 0.01), REACH, GAIN, OMEGA, 0.4, None)
    away = foothold_shift(error, STRAIGHT, (0.0, -0.01), REACH, GAIN, OMEGA, 0.4, None)
    reach = REACH[1] - 0.01
    assert towards[1] == pytest.approx(reach + (0.04 - reach) * math.exp(OMEGA * 0.4))
    assert away[1] < centred[1] < towards[1]


@pytest.mark.parametrize('yaw_rad', [0.5, -2.0, 3.0])
def test_a_turned_sole_turns_the_shift_with_it(yaw_rad: float) -> None:
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    rotation = np.array([[c, -s], [s, c]])
    local_error, local_offset = np.array([0.13, -0.06]), np.array([0.01, 0.005])
    straight = foothold_shift(tuple(local_error), STRAIGHT, tuple(local_offset), REACH, GAIN,
                              OMEGA, 0.3, 0.63)
    turned = foothold_shift(tuple(rotation @ local_error), (c, s),
                            tuple(rotation @ local_offset), REACH, GAIN, OMEGA, 0.3, 0.63)
    assert turned == pytest.approx(tuple(rotation @ np.array(straight)), abs=1e-12)
