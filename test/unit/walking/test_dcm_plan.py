"""The capture point's plan: continuous, at rest at the end, and tracked by its law."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tutorial_atlas_control.balance.lipm import dcm_feedback_cop, natural_frequency
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.walking import WalkingError
from tutorial_atlas_control.walking.dcm_plan import DcmPlan

OMEGA = natural_frequency(0.85)
COPS = np.array([[0.0, -0.12], [0.2, 0.12], [0.4, -0.12], [0.6, 0.12]])
DURATIONS = np.array([0.63, 0.63, 0.5, 0.7])
FINAL = np.array([0.6, 0.0])


def test_the_plan_is_continuous_and_ends_at_rest_on_the_final_point() -> None:
    plan = DcmPlan.plan(COPS, DURATIONS, FINAL, OMEGA)
    for i in range(len(COPS) - 1):
        end, _ = plan.reference(i, DURATIONS[i])
        start, _ = plan.reference(i + 1, 0.0)
        assert end == pytest.approx(start, abs=1e-12)
    assert plan.reference(3, DURATIONS[3])[0] == pytest.approx(FINAL)
    assert plan.reference(0, 0.0)[0] == pytest.approx(plan.start)


def test_the_reference_obeys_the_capture_points_dynamics() -> None:
    plan = DcmPlan.plan(COPS, DURATIONS, FINAL, OMEGA)
    h = 1e-6
    for step, t in ((0, 0.1), (1, 0.4), (3, 0.6)):
        xi, cop = plan.reference(step, t)
        rate = (plan.reference(step, t + h)[0] - plan.reference(step, t - h)[0]) / (2 * h)
        assert rate == pytest.approx(OMEGA * (xi - cop), rel=1e-6)


def test_the_law_with_the_plans_pressure_centre_makes_the_error_decay_at_omega_gain() -> None:
    plan = DcmPlan.plan(COPS, DURATIONS, FINAL, OMEGA)
    gain, dt = 2.0, 1e-4
    xi = plan.start + np.array([0.02, -0.01])
    error0 = np.linalg.norm(xi - plan.start)
    t = 0.0
    while t < 0.5:
        xi_ref, cop_ref = plan.reference(0, t)
        xi = xi + dt * OMEGA * (xi - dcm_feedback_cop(xi, xi_ref, gain, cop_ref))
        t += dt
    error = np.linalg.norm(xi - plan.reference(0, t)[0])
    assert error == pytest.approx(error0 * math.exp(-OMEGA * gain * t), rel=1e-2)


@pytest.mark.parametrize('durations, message', [
    (np.array([0.63, 0.63, 0.0, 0.63]), 'positive'),
    (np.array([0.63]), 'one duration per pressure centre'),
])
def test_bad_plans_are_refused(durations: np.ndarray, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        DcmPlan.plan(COPS, durations, FINAL, OMEGA)


def test_a_bad_plan_raises_the_walks_error() -> None:
    with pytest.raises(WalkingError, match='every step duration must be positive') as raised:
        DcmPlan.plan(COPS, -DURATIONS, FINAL, OMEGA)
    assert isinstance(raised.value, AtlasControlError)  # what the command lines catch
