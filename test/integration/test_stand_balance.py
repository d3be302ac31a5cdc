"""Stand balances, offline and deterministic: ten seconds in DRCSim's Stand pose, and
0.2 s pelvis pushes (the /atlas/apply_pelvis_force input) forward, backward and sideways
survived without a step. The figures are the largest impulses found in 5 N s steps (see
docs/controllers.md); the planted defect (no capture-point correction) falls at the same pushes.

About 1 s of CPU per simulated second. Also the take-over from the hold's straight legs
(the Stand pose reached over TRANSITION_S; at once, the planted defect, it falls).
"""

from __future__ import annotations

import numpy as np
import pytest

from tutorial_atlas_control.balance import STAND_POSE_RAD, TRANSITION_S, StandBehaviour
from tutorial_atlas_control.balance.push_trial import (
    FOOT_TRAVEL_LIMIT_M,
    STANDING_PELVIS_M,
    push_survived,
    stand_trial,
)
from tutorial_atlas_control.balance.stand import StandGains
from tutorial_atlas_control.joints import JOINT_INDEX
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    AtlasSimulator,
    ControlMode,
    VrcMode,
    load_gains_yaml,
    load_model,
    pelvis_height_m,
)

KNEES = [JOINT_INDEX['l_leg_kny'], JOINT_INDEX['r_leg_kny']]

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


def stand_after_the_hold(transition_s: float) -> tuple[AtlasSimulator, float]:
    """The port's start-up (pinned 1 s, then the hold's straight legs) for 2 s, then the
    balancing Stand taking over for 4 s; (the simulator, how far a sole moved (m))."""
    atlas = load_model()
    sim = AtlasSimulator(atlas, load_gains_yaml(DEFAULT_GAINS_FILE), time_to_unpin_s=1.0)
    for _ in range(2000):
        sim.step()
    stand = StandBehaviour(atlas, transition_s=transition_s)
    sim.install_stand(stand)
    assert stand.last_state is not None
    feet = stand.last_state.sole_centres[:, :2].copy()
    for _ in range(4000):
        sim.step()
    travel = float(np.max(np.linalg.norm(stand.last_state.sole_centres[:, :2] - feet, axis=1)))
    return sim, travel


def test_stand_takes_over_from_the_hold_and_bends_to_the_stand_pose() -> None:
    """From the hold's straight legs, within TRANSITION_S, to DRCSim's Stand pose: knees
    0.518 rad, the pelvis about 0.91 m, the feet where they were."""
    sim, travel = stand_after_the_hold(TRANSITION_S)
    np.testing.assert_allclose(sim.joint_positions()[KNEES], STAND_POSE_RAD[KNEES], atol=0.01)
    assert pelvis_height_m(sim.atlas, sim.data) == pytest.approx(0.912, abs=0.01)
    assert travel < 0.001


def test_without_the_transition_stand_does_not_take_over() -> None:
    """The planted defect: the Stand pose's reference at once, from straight legs, falls."""
    sim, _ = stand_after_the_hold(0.0)
    assert pelvis_height_m(sim.atlas, sim.data) < STANDING_PELVIS_M


def test_drcsim_2_7_start_lands_and_balances() -> None:
    """startup_mode bdi_stand (DRCSim 2.6/2.7's start): pinned in the Stand pose, dropped at
    1 s, the balancing Stand from 2 s with every k_effort 0: standing at the Stand's height,
    the feet still, at 8 s."""
    atlas = load_model()
    sim = AtlasSimulator(atlas, load_gains_yaml(DEFAULT_GAINS_FILE),
                         startup_mode=VrcMode.BDI_STAND)
    stand = StandBehaviour(atlas)
    sim.install_stand(stand)
    for _ in range(2500):
        sim.step()
    assert sim.mode is ControlMode.STAND and stand.last_state is not None
    np.testing.assert_array_equal(sim.active_k_effort(), 0)  # AtlasState: f_out alone
    feet = stand.last_state.sole_centres[:, :2].copy()
    lowest = np.inf
    for _ in range(5500):
        sim.step()
        lowest = min(lowest, pelvis_height_m(sim.atlas, sim.data))
    travel = float(np.max(np.linalg.norm(stand.last_state.sole_centres[:, :2] - feet, axis=1)))
    print(f'\nbdi_stand start: pelvis {pelvis_height_m(sim.atlas, sim.data):.4f} m at 8 s, '
          f'lowest {lowest:.4f} m from 2.5 s, feet moved {travel * 1000:.2f} mm')
    assert pelvis_height_m(sim.atlas, sim.data) == pytest.approx(0.912, abs=0.01)
    assert lowest > STANDING_PELVIS_M
    assert travel < 0.001
