"""Stand balances, offline and deterministic: ten seconds in DRCSim's Stand pose, and
0.2 s pelvis pushes (the /atlas/apply_pelvis_force input) forward, backward and sideways
survived without a step. The figures are the largest impulses found in 5 N s steps (see
docs/controllers.md); the planted defect (no capture-point correction) falls at the same pushes.

About 1 s of CPU per simulated second: ~50 s in all.
"""

from __future__ import annotations

import pytest

from tutorial_atlas_control.balance.push_trial import (
    FOOT_TRAVEL_LIMIT_M,
    STANDING_PELVIS_M,
    push_survived,
    stand_trial,
)
from tutorial_atlas_control.balance.stand import StandGains

#: The largest impulses (N s) survived, per direction (unit vector), found in 5 N s steps.
SURVIVED = {'forward': ((1.0, 0.0), 45.0), 'backward': ((-1.0, 0.0), 45.0),
            'left': ((0.0, 1.0), 60.0), 'right': ((0.0, -1.0), 60.0)}
#: The goals of the open AtlasSimInterface's Stand (N s).
GOALS = {'forward': 40.0, 'backward': 25.0, 'left': 40.0, 'right': 40.0}


def test_stand_holds_ten_seconds_in_place() -> None:
    result = stand_trial(10.0)
    assert result.stood
    assert result.lowest_pelvis_m > 0.9  # Stand's pelvis, about 0.91 m
    assert result.foot_travel_m < 0.001


@pytest.mark.parametrize('direction', sorted(SURVIVED))
def test_the_largest_push_found_is_survived_without_a_step(direction: str) -> None:
    unit, impulse = SURVIVED[direction]
    assert impulse >= GOALS[direction]
    result = push_survived(unit, impulse)
    assert result.stood, result
    assert result.lowest_pelvis_m > STANDING_PELVIS_M
    assert result.foot_travel_m <= FOOT_TRAVEL_LIMIT_M


@pytest.mark.parametrize('direction', sorted(SURVIVED))
def test_5_ns_more_falls_or_steps(direction: str) -> None:
    """The figure is the edge: 5 N s more is not survived in place."""
    unit, impulse = SURVIVED[direction]
    assert not push_survived(unit, impulse + 5.0).stood


@pytest.mark.parametrize('direction', ['forward', 'left'])
def test_without_capture_point_correction_the_same_push_is_not_survived(
        direction: str) -> None:
    """The planted defect: gain 0 puts the pressure centre on the capture point, which
    then stops but never returns."""
    unit, impulse = SURVIVED[direction]
    assert not push_survived(unit, impulse, StandGains(capture_gain=0.0)).stood


def test_a_trial_is_deterministic() -> None:
    """Offline runs replay: the same push gives the same motion, to the bit."""
    first, second = (push_survived((0.0, 1.0), 30.0) for _ in range(2))
    assert (first.lowest_pelvis_m, first.foot_travel_m, first.steps) == (
        second.lowest_pelvis_m, second.foot_travel_m, second.steps)
