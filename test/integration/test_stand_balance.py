"""Stand balances, offline and deterministic: ten seconds in DRCSim's Stand pose, and
0.2 s pelvis pushes (the /atlas/apply_pelvis_force input) forward, backward and sideways
survived without a step. The figures are the largest impulses found in 5 N s steps (see
docs/controllers.md); the planted defect (no capture-point correction) falls at the same pushes.

About 0.2 s of CPU per simulated second. Also the take-over from the hold's straight legs
(the Stand pose reached over TRANSITION_S; at once, the planted defect, it falls), DRCSim
2.7's start, the harness drop of DRCSim's scripts, and the arms swung under the user's PID
while Stand balances the rest.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

from support.arm_swing import ARMS, arm_command, swung
from tutorial_atlas_control.asi import AtlasSimInterface, Behavior
from tutorial_atlas_control.balance import StandBehaviour
from tutorial_atlas_control.balance.push_trial import (
    FOOT_TRAVEL_LIMIT_M,
    TrialResult,
    push_survived,
    stand_trial,
)
from tutorial_atlas_control.balance.stand import StandGains, pitch_of, yaw_of
from tutorial_atlas_control.balance.stand_behaviour import TRANSITION_S
from tutorial_atlas_control.joints import JOINT_INDEX
from tutorial_atlas_control.msgs.atlas_sim_interface import AsiCommand, ManipulateParams, StepData
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    STAND_POSE_RAD,
    STANDING_PELVIS_M,
    AtlasSimulator,
    ControlMode,
    ModeInput,
    VrcMode,
    load_gains_yaml,
    load_model,
    pelvis_height_m,
)

#: Offline (no ROS, no claim about time): `make test` runs it at the lowest priority beside
#: the serial tests, on the CPU they leave idle.
pytestmark = pytest.mark.offline

KNEES = [JOINT_INDEX['l_leg_kny'], JOINT_INDEX['r_leg_kny']]
HIP_ROLLS = [JOINT_INDEX['l_leg_mhx'], JOINT_INDEX['r_leg_mhx']]

#: The largest impulses (N s) survived, per direction (unit vector), found in 5 N s steps.
SURVIVED = {'forward': ((1.0, 0.0), 45.0), 'backward': ((-1.0, 0.0), 45.0),
            'left': ((0.0, 1.0), 60.0), 'right': ((0.0, -1.0), 60.0)}
#: The goals of the open AtlasSimInterface's Stand (N s).
GOALS = {'forward': 40.0, 'backward': 25.0, 'left': 40.0, 'right': 40.0}


@cache
def largest_push_survived(direction: str) -> TrialResult:
    """The push of SURVIVED[direction], run once in the module: the largest-push test judges
    it and the determinism test runs it again."""
    unit, impulse = SURVIVED[direction]
    return push_survived(unit, impulse)


def test_stand_holds_ten_seconds_in_place() -> None:
    result = stand_trial(10.0)
    assert result.stood
    assert result.lowest_pelvis_m > 0.9  # Stand's pelvis, about 0.91 m
    assert result.foot_travel_m < 0.001


@pytest.mark.parametrize('direction', sorted(SURVIVED))
def test_the_largest_push_found_is_survived_without_a_step(direction: str) -> None:
    assert SURVIVED[direction][1] >= GOALS[direction]
    result = largest_push_survived(direction)
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
    """Offline runs replay: the same push gives the same motion, to the bit (the largest
    left push, at the edge of what is survived, run again)."""
    unit, impulse = SURVIVED['left']
    first, second = largest_push_survived('left'), push_survived(unit, impulse)
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
    """From the hold's straight legs, within TRANSITION_S, to DRCSim's Stand pose carried to
    the hold's stance: its feet are 0.18 m apart where the Stand pose's are 0.28 m, so the
    hips stay unrolled (the Stand pose's 0.062 rad would push the soles apart) and the knees
    bend to 0.529 rad (the Stand pose's 0.518); the pelvis about 0.91 m, the feet where
    they were."""
    sim, travel = stand_after_the_hold(TRANSITION_S)
    joints = sim.joint_positions()
    np.testing.assert_allclose(joints[KNEES], 0.529, atol=0.002)
    np.testing.assert_allclose(joints[HIP_ROLLS], 0.0, atol=0.002)
    np.testing.assert_allclose(joints[KNEES], STAND_POSE_RAD[KNEES], atol=0.015)
    assert pelvis_height_m(sim.atlas, sim.data) == pytest.approx(0.912, abs=0.01)
    assert travel < 0.001


def test_without_the_transition_stand_does_not_take_over() -> None:
    """The planted defect: the Stand pose's reference at once, from straight legs, falls."""
    sim, _ = stand_after_the_hold(0.0)
    assert pelvis_height_m(sim.atlas, sim.data) < STANDING_PELVIS_M


def test_drcsim_2_7_start_lands_and_balances() -> None:
    """startup_mode bdi_stand (DRCSim 2.6/2.7's start): pinned in the Stand pose under the
    user's PID (User, k_effort 255) at 0.5 s, dropped at 1 s, the balancing Stand from 2 s
    with every k_effort 0: standing at the Stand's height,
    the feet still, at 8 s."""
    atlas = load_model()
    sim = AtlasSimulator(atlas, load_gains_yaml(DEFAULT_GAINS_FILE),
                         startup_mode=VrcMode.BDI_STAND)
    stand = StandBehaviour(atlas)
    sim.install_stand(stand)
    for _ in range(500):
        sim.step()
    assert sim.mode is ControlMode.USER  # pinned in the Stand pose under the user's PID
    np.testing.assert_array_equal(sim.active_k_effort(), 255)
    for _ in range(2000):
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


def run_for(sim: AtlasSimulator, seconds: float) -> float:
    """Step `seconds`; the lowest pelvis height (m) on the way."""
    lowest = np.inf
    for _ in range(int(round(seconds / sim.dt_s))):
        sim.step()
        lowest = min(lowest, pelvis_height_m(sim.atlas, sim.data))
    return lowest


def balancing_simulator() -> AtlasSimulator:
    """The port's start (pinned 1 s), Stand the balancing one."""
    atlas = load_model()
    sim = AtlasSimulator(atlas, load_gains_yaml(DEFAULT_GAINS_FILE))
    sim.install_stand(StandBehaviour(atlas))
    return sim


def test_harness_drop_lands_and_stands() -> None:
    """DRCSim's scripts: /atlas/mode harnessed, StandPrep, 5 s, nominal, 0.3 s, Stand: the
    robot lands (feet 4.3 cm above the ground in the harness) and stands 10 s."""
    sim = AtlasSimulator(load_model(), load_gains_yaml(DEFAULT_GAINS_FILE))
    AtlasSimInterface(sim)  # installs the balancing Stand and StandPrep
    run_for(sim, 1.5)
    sim.apply_input(ModeInput(VrcMode.HARNESSED))
    sim.set_mode(ControlMode.STAND_PREP)
    run_for(sim, 5.0)
    assert pelvis_height_m(sim.atlas, sim.data) == pytest.approx(0.97, abs=0.005)
    sim.apply_input(ModeInput(VrcMode.NOMINAL))
    landing = run_for(sim, 0.3)
    sim.set_mode(ControlMode.STAND)
    standing = run_for(sim, 10.0)
    end = pelvis_height_m(sim.atlas, sim.data)
    print(f'\nharness drop: lowest {landing:.4f} m landing, {standing:.4f} m over 10 s of Stand, '
          f'{end:.4f} m at the end')
    assert standing > STANDING_PELVIS_M
    assert end == pytest.approx(0.912, abs=0.01)


#: The arms swing through this range (rad), about the Stand pose, at SWING_HZ.
SWING_RAD = 1.5
SWING_HZ = 0.5
#: Mixed control's goal: the pelvis moves less than this (m) while the arms swing.
PELVIS_MOVE_M = 0.05


@pytest.mark.parametrize('joint', ['usy', 'shx'])
def test_arms_swung_under_the_users_pid_while_stand_balances(joint: str) -> None:
    """Both arms swung through SWING_RAD (shoulder pitch or roll, 4 s) under the user's PID:
    Stand keeps the robot up with the pelvis within PELVIS_MOVE_M of where it stood."""
    sim = balancing_simulator()
    run_for(sim, 3.0)
    adr = sim.atlas.free_qpos_adr
    start = sim.data.qpos[adr:adr + 3].copy()
    moved = 0.0
    for k in range(4000):
        if k % 20 == 0:  # the tutorial's 50 Hz
            sim.receive_updates(arm_command(swung(joint, SWING_RAD, SWING_HZ, k * sim.dt_s),
                                            sim.gains))
        sim.step()
        moved = max(moved, float(np.linalg.norm(sim.data.qpos[adr:adr + 3] - start)))
    arms = [JOINT_INDEX[name] for name in ARMS]
    assert (sim.active_k_effort()[arms] == 255).all()
    print(f'\narm swing ({joint}): the pelvis moved at most {moved * 100:.2f} cm')
    assert moved < PELVIS_MOVE_M
    assert pelvis_height_m(sim.atlas, sim.data) > STANDING_PELVIS_M


#: Manipulate's goal: the pelvis within these of its target 2 s after a request (m, rad).
SERVO_HEIGHT_M = 0.02
SERVO_YAW_RAD = 0.05


def test_manipulate_tracks_pelvis_height_and_yaw() -> None:
    """Through the AtlasSimInterface: Manipulate with use_desired, 2 s per target, down into
    the tipped squat (0.75 m: below what the legs reach with the pelvis level, the ankles'
    0.698 rad), up out of it, and turned both ways; on the way, never lower than the lower
    of the two targets less the goal's 2 cm."""
    sim = balancing_simulator()
    interface = AtlasSimInterface(sim)  # installs its own balancing Stand
    stand = interface.stand
    assert stand is not None
    run_for(sim, 3.0)
    previous_m = STANDING_PELVIS_M
    for height, yaw in ((0.75, 0.0), (0.85, 0.0), (0.85, 0.3), (0.75, -0.3), (0.85, 0.3)):
        interface.apply(AsiCommand(0, Behavior.MANIPULATE, (StepData(),) * 4, False,
                                   StepData(), False, ManipulateParams(True, height, yaw, 0.0),
                                   None, 0))
        clamped = interface.state().manipulate_feedback
        assert (clamped.pelvis_height_m, clamped.pelvis_yaw_rad) == (height, yaw)
        lowest = run_for(sim, 2.0)
        state = stand.last_state
        assert state is not None
        soles_m = float(state.sole_centres[:, 2].mean())
        pelvis_m = pelvis_height_m(sim.atlas, sim.data) - soles_m
        headings = state.sole_rotations[:, 0:2, 0].sum(axis=0)
        turned = yaw_of(state.pelvis_rotation) - float(np.arctan2(headings[1], headings[0]))
        print(f'\nmanipulate {height} m, {yaw} rad: after 2 s {pelvis_m:.4f} m, '
              f'{turned:.4f} rad, pitched {pitch_of(state.pelvis_rotation):.3f} rad; lowest '
              f'{lowest - soles_m:.4f} m')
        assert lowest - soles_m > min(height, previous_m) - SERVO_HEIGHT_M
        previous_m = height
        assert abs(pelvis_m - height) < SERVO_HEIGHT_M
        assert abs(turned - yaw) < SERVO_YAW_RAD
