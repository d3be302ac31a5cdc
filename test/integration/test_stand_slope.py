"""The balancing Stand on a slope (balance/slope_trial.py): Atlas's world with its floor
tilted 8 degrees, the robot placed facing up it with its soles on the incline, each start
perturbed by a seed (walking/start_noise.py). Stand, with its default solver (inverse
statics: docs/controllers.md, "Solver"), holds it in place from every seed."""

from __future__ import annotations

import math

import pytest

from tutorial_atlas_control.balance import StandGains
from tutorial_atlas_control.balance.slope_trial import slope_stand_trial
from tutorial_atlas_control.walking import perturb_start

#: Offline (no ROS, no claim about time): `make test` runs it at the lowest priority beside
#: the serial tests, on the CPU they leave idle.
pytestmark = pytest.mark.offline

SLOPE_RAD = math.radians(8.0)
SEEDS = range(8)
#: Past Stand's 1 s start (the reference brought to the Stand pose) and settled.
TRIAL_S = 3.0


@pytest.mark.parametrize('seed', SEEDS)
def test_stand_holds_on_an_8_degree_slope(seed: int) -> None:
    result = slope_stand_trial(
        SLOPE_RAD, StandGains(), TRIAL_S,
        perturb=lambda atlas, data: perturb_start(atlas, data, seed, on_ground=False))
    assert result.stood, result
    assert result.lowest_pelvis_m > 0.88  # Stand's pelvis, 0.903 m above the slope
    assert result.sole_travel_m < 0.01    # the placement's settling: 2.5-5 mm
    assert result.cop_margin_m > 0.03     # each pressure centre well inside its sole
