"""Walk's pure parts: the sway's pressure centre and a foot's pose as a step."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tutorial_atlas_control.walking.walk import sway_cop


def test_the_sway_s_pressure_centre_takes_the_capture_point_to_its_target() -> None:
    omega, duration = 3.4, 0.6
    start, target = np.array([0.02, 0.0]), np.array([0.05, -0.08])
    cop = sway_cop(start, target, omega, duration)
    # xi' = omega (xi - p) from start for `duration`, integrated exactly.
    end = cop + (start - cop) * math.exp(omega * duration)
    assert end == pytest.approx(target, abs=1e-12)
    # The pressure centre lies behind the start, away from the target (it pushes xi there).
    assert np.dot(cop - start, target - start) < 0.0
