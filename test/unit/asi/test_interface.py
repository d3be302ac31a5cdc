"""AtlasSimInterface over a simulator: Stand is the balancing behaviour, requests switch
behaviours without touching k_effort, k_effort taken at 28 entries only, and the state
reports Freeze and StandPrep truly, f_out, the pelvis, the feet and falling."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.asi import (
    AsiError,
    AtlasSimInterface,
    Behavior,
    Status,
)
from tutorial_atlas_control.balance import place_in_stand_pose
from tutorial_atlas_control.control_modes import ControlMode
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.msgs.atlas_sim_interface import (
    AsiCommand,
    ManipulateParams,
    StepData,
)
from tutorial_atlas_control.msgs.atlas_sim_interface_state import encode_asi_state
from tutorial_atlas_control.sim import AtlasSimulator, GroundUnderFeet, load_gains_yaml, load_model
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.vrc import ModeInput, VrcMode, WrenchInput

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'


@pytest.fixture(scope='module')
def atlas() -> atlas_model.AtlasModel:
    return load_model()


@pytest.fixture
def interface(atlas: atlas_model.AtlasModel) -> AtlasSimInterface:
    """Standing in DRCSim's Stand pose, free, in Stand."""
    sim = AtlasSimulator(atlas, load_gains_yaml(CONFIG), time_to_unpin_s=0.0)
    place_in_stand_pose(sim.atlas, sim.data)
    return AtlasSimInterface(sim)


def command(behavior: int, k_effort: np.ndarray | None = None,
            length: int | None = None) -> AsiCommand:
    return AsiCommand(0, behavior, (StepData(),) * 4, False, StepData(), False,
                      ManipulateParams(), k_effort,
                      NUM_JOINTS if length is None else length)


def run(interface: AtlasSimInterface, steps: int) -> None:
    for _ in range(steps):
        interface.sim.step()
        interface.end_step()


def test_stand_is_the_balancing_behaviour_and_reported(interface: AtlasSimInterface) -> None:
    run(interface, 200)
    sim = interface.sim
    assert sim.behaviours.acting is interface.stand
    state = interface.state()
    assert (state.current_behavior, state.desired_behavior) == (Behavior.STAND, Behavior.STAND)
    assert state.behavior_feedback.status_flags == Status.OK
    np.testing.assert_array_equal(state.f_out_nm, sim.torque_nm)  # no user joints
    np.testing.assert_array_equal(state.k_effort, np.zeros(NUM_JOINTS, np.uint8))
    assert state.pelvis_position_m[2] == pytest.approx(0.91, abs=0.01)
    left, right = state.foot_poses
    assert left[1] > 0.05 and right[1] < -0.05  # left foot on the left (y > 0)
    np.testing.assert_allclose(np.linalg.norm(state.foot_poses[:, 3:], axis=1), 1.0)
    assert len(encode_asi_state(state)) > 0


@pytest.mark.parametrize(('behavior', 'mode'), [(Behavior.FREEZE, ControlMode.FREEZE),
                                                (Behavior.STAND_PREP, ControlMode.STAND_PREP),
                                                (Behavior.USER, ControlMode.USER)])
def test_each_served_behaviour_is_reported_as_itself(interface: AtlasSimInterface,
                                                     behavior: Behavior,
                                                     mode: ControlMode) -> None:
    """DRCSim reported Freeze and StandPrep as 0: not copied."""
    interface.apply(command(behavior))
    assert interface.sim.mode is mode
    state = interface.state()
    assert state.current_behavior == behavior != 0
    assert state.behavior_feedback.status_flags == Status.TRANSITION_SUCCESS
    interface.end_step()
    assert interface.state().behavior_feedback.status_flags == Status.OK


def test_k_effort_is_taken_at_28_entries_and_a_switch_keeps_it(
        interface: AtlasSimInterface) -> None:
    arms = np.zeros(NUM_JOINTS)
    arms[16:] = 1.0
    interface.apply(command(Behavior.STAND, arms))
    expected = (arms * 255).astype(np.uint8)
    np.testing.assert_array_equal(interface.sim.active_k_effort(), expected)
    interface.apply(command(Behavior.STAND, None, length=27))
    np.testing.assert_array_equal(interface.sim.active_k_effort(), expected)  # kept
    interface.apply(command(Behavior.FREEZE))
    assert interface.sim.mode is ControlMode.FREEZE
    np.testing.assert_array_equal(interface.sim.active_k_effort(), expected)  # not reset


def test_streaming_the_running_stand_changes_nothing(atlas: atlas_model.AtlasModel) -> None:
    """A client requesting STAND every step: the run is bit for bit a run without it."""
    twins = []
    for _ in range(2):
        sim = AtlasSimulator(atlas, load_gains_yaml(CONFIG), time_to_unpin_s=0.0)
        place_in_stand_pose(sim.atlas, sim.data)
        twins.append(AtlasSimInterface(sim))
    streamed, quiet = twins
    for _ in range(300):
        streamed.apply(command(Behavior.STAND))
        for twin in twins:
            twin.sim.step()
            twin.end_step()
    assert streamed.sim.data.qpos.tobytes() == quiet.sim.data.qpos.tobytes()
    assert streamed.state().behavior_feedback.status_flags == Status.OK


def test_stand_is_refused_for_a_fallen_robot_which_reports_falling_in_stand(
        interface: AtlasSimInterface) -> None:
    sim = interface.sim
    sim.set_mode(ControlMode.RAGDOLL)
    run(interface, 3000)  # limp: it falls
    assert interface.state().current_behavior == Behavior.USER
    interface.apply(command(Behavior.STAND))
    assert sim.mode is ControlMode.RAGDOLL
    state = interface.state()
    assert state.behavior_feedback.status_flags == Status.FAILED_TRANS_COM_POS
    assert state.error_code == AsiError.FAILED_TO_START_BEHAVIOR
    sim.set_mode(ControlMode.STAND)  # /atlas/control_mode Stand is not refused
    assert GroundUnderFeet(sim.atlas, sim.data).falling()
    assert interface.state().behavior_feedback.status_flags == Status.ERROR_FALLING


def test_a_push_beyond_what_stand_survives_is_reported_falling(
        interface: AtlasSimInterface) -> None:
    sim = interface.sim
    run(interface, 500)
    assert not GroundUnderFeet(sim.atlas, sim.data).falling()
    sim.apply_input(WrenchInput((1000.0, 0.0, 0.0), (0.0, 0.0, 0.0)))  # 200 N s
    run(interface, 200)
    sim.apply_input(WrenchInput((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
    flags = []
    for _ in range(3000):
        run(interface, 1)
        flags.append(interface.state().behavior_feedback.status_flags)
    assert flags[0] == Status.OK and flags[-1] == Status.ERROR_FALLING
    pelvis = sim.data.xpos[sim.atlas.pelvis_body_id]
    assert pelvis[2] < 0.7 or math.acos(sim.data.xmat[sim.atlas.pelvis_body_id][8]) > 0.5


def test_a_switch_made_elsewhere_is_reported_once(interface: AtlasSimInterface) -> None:
    """/atlas/control_mode Freeze: the next state says Stand -> Freeze succeeded, then OK."""
    run(interface, 10)
    interface.sim.set_mode(ControlMode.FREEZE)
    interface.sim.step()
    state = interface.state()
    assert state.current_behavior == Behavior.FREEZE == state.desired_behavior
    feedback = state.behavior_feedback
    assert feedback.status_flags == Status.TRANSITION_SUCCESS
    assert (feedback.trans_from_behavior_index, feedback.trans_to_behavior_index) == (0, 2)
    interface.end_step()
    run(interface, 1)
    assert interface.state().behavior_feedback.status_flags == Status.OK


def test_without_balance_stand_is_the_hold(atlas: atlas_model.AtlasModel) -> None:
    sim = AtlasSimulator(atlas, load_gains_yaml(CONFIG))
    interface = AtlasSimInterface(sim, balance=False)
    assert sim.behaviours.acting is None and sim.behaviours.stand is None
    run(interface, 5)
    np.testing.assert_array_equal(interface.state().f_out_nm, sim.torque_nm)  # the hold's


def manipulate(height_m: float, yaw_rad: float = 0.0, lateral_m: float = 0.0,
               use_desired: bool = True) -> AsiCommand:
    return AsiCommand(0, Behavior.MANIPULATE, (StepData(),) * 4, False, StepData(), False,
                      ManipulateParams(use_desired, height_m, yaw_rad, lateral_m), None, 0)


def test_manipulate_servoes_stand_and_reports_the_clamped_targets(
        interface: AtlasSimInterface) -> None:
    run(interface, 10)
    interface.apply(manipulate(0.5, 1.0, -0.2))  # beyond reach every way
    assert interface.sim.mode is ControlMode.STAND and interface.manipulating
    state = interface.state()
    assert state.current_behavior == Behavior.MANIPULATE == state.desired_behavior
    assert state.behavior_feedback.status_flags == Status.TRANSITION_SUCCESS
    clamped = state.manipulate_feedback
    squats = interface.stand.squats
    assert (clamped.pelvis_height_m, clamped.pelvis_yaw_rad, clamped.pelvis_lat_m) == (
        squats.height_range_m[0], squats.yaw_limit_rad, -0.05)
    target = interface.stand.servo_target
    interface.end_step()
    run(interface, 5)
    interface.apply(manipulate(0.5, 1.0, -0.2))  # streamed: the same target, no restart
    assert interface.stand.servo_target is target
    assert interface.state().behavior_feedback.status_flags == Status.OK
    interface.apply(manipulate(0.0, use_desired=False))  # Stand's own pose
    assert interface.stand.servo_target is None
    assert interface.state().manipulate_feedback.pelvis_height_m == pytest.approx(
        squats.stand_height_m)
    interface.apply(command(Behavior.STAND))
    state = interface.state()
    assert state.current_behavior == Behavior.STAND and not interface.manipulating
    assert state.manipulate_feedback.pelvis_height_m == 0.0


def test_control_mode_stand_ends_manipulate(interface: AtlasSimInterface) -> None:
    interface.apply(manipulate(0.85))
    interface.end_step()
    interface.sim.set_mode(ControlMode.STAND)  # /atlas/control_mode Stand: Stand restarts
    interface.sim.step()
    state = interface.state()
    assert state.current_behavior == Behavior.STAND
    assert (state.behavior_feedback.trans_from_behavior_index,
            state.behavior_feedback.trans_to_behavior_index) == (Behavior.MANIPULATE,
                                                                 Behavior.STAND)


def test_without_balance_manipulate_is_not_served(atlas: atlas_model.AtlasModel) -> None:
    interface = AtlasSimInterface(AtlasSimulator(atlas, load_gains_yaml(CONFIG)), balance=False)
    interface.apply(manipulate(0.85))
    state = interface.state()
    assert state.current_behavior == Behavior.STAND and not interface.manipulating
    assert state.behavior_feedback.status_flags == Status.FAILED_TRANS_ILLEGAL_BEHAVIOR
    assert state.error_code == AsiError.BEHAVIOR_NOT_IMPLEMENTED


def test_bdi_stand_loads_the_balancing_stand_into_a_hold_session(
        atlas: atlas_model.AtlasModel) -> None:
    """stand:=hold, then /atlas/mode bdi_stand: its Stand at 2 s is the balancing one."""
    sim = AtlasSimulator(atlas, load_gains_yaml(CONFIG))
    interface = AtlasSimInterface(sim, balance=False)
    run(interface, 1500)
    assert interface.stand is None and sim.behaviours.acting is None
    sim.apply_input(ModeInput(VrcMode.BDI_STAND))
    run(interface, 2100)
    assert sim.mode is ControlMode.STAND
    assert interface.stand is not None and sim.behaviours.acting is interface.stand
    assert interface.session.served[Behavior.MANIPULATE] is ControlMode.STAND


def one_step_walk(step_index: int) -> AsiCommand:
    """A WALK of one left step 0.2 m ahead with `step_index`."""
    step = StepData(step_index, 0, 0.63, (0.2, 0.12, 0.0), (0.0, 0.0, 0.0, 1.0), 0.1)
    return AsiCommand(0, Behavior.WALK, (step,) + (StepData(),) * 3, False, StepData(), False,
                      ManipulateParams(), None, 0)


@pytest.fixture
def waiting(atlas: atlas_model.AtlasModel) -> AtlasSimInterface:
    """atlas.launch's default start: pinned for 1 s, the library loaded but waiting."""
    sim = AtlasSimulator(atlas, load_gains_yaml(CONFIG))
    return AtlasSimInterface(sim, hold_at_start=True)


def test_the_default_start_holds_as_the_tutorial_did_and_says_user(
        waiting: AtlasSimInterface) -> None:
    sim = waiting.sim
    run(waiting, 1500)  # past the pin's release at 1 s
    assert sim.mode is ControlMode.STAND and sim.behaviours.acting is None
    state = waiting.state()
    assert state.current_behavior == Behavior.USER
    np.testing.assert_array_equal(state.k_effort, np.full(NUM_JOINTS, 255, np.uint8))
    np.testing.assert_array_equal(state.f_out_nm, np.zeros(NUM_JOINTS))
    # The tutorial's hold: the initial pose, straight legs, the pelvis where it started.
    assert state.pelvis_position_m[2] == pytest.approx(0.927, abs=0.005)


def test_an_asi_stand_from_the_default_start_hands_the_robot_to_the_balancing_stand(
        waiting: AtlasSimInterface) -> None:
    sim = waiting.sim
    run(waiting, 1500)
    waiting.apply(command(Behavior.STAND, np.zeros(NUM_JOINTS)))
    assert waiting.take_refusal() is None
    assert sim.behaviours.acting is waiting.stand
    state = waiting.state()
    assert (state.current_behavior, state.behavior_feedback.status_flags) == (
        Behavior.STAND, Status.TRANSITION_SUCCESS)
    assert (state.behavior_feedback.trans_from_behavior_index,
            state.behavior_feedback.trans_to_behavior_index) == (Behavior.USER, Behavior.STAND)
    run(waiting, 2000)
    state = waiting.state()
    assert state.current_behavior == Behavior.STAND
    np.testing.assert_array_equal(state.k_effort, np.zeros(NUM_JOINTS, np.uint8))
    assert state.pelvis_position_m[2] == pytest.approx(0.91, abs=0.01)  # the Stand's height


def test_control_mode_stand_gets_the_balancing_stand_and_a_reset_the_hold_again(
        waiting: AtlasSimInterface) -> None:
    sim = waiting.sim
    run(waiting, 10)
    sim.set_mode(ControlMode.STAND)  # /atlas/control_mode Stand
    assert sim.behaviours.acting is waiting.stand
    state = waiting.state()
    assert (state.current_behavior, state.behavior_feedback.status_flags) == (
        Behavior.STAND, Status.TRANSITION_SUCCESS)
    run(waiting, 10)
    sim.reset_world()
    assert sim.behaviours.acting is None
    assert waiting.state().current_behavior == Behavior.USER


def test_walk_from_the_default_start_is_refused_in_one_line_naming_stand(
        waiting: AtlasSimInterface) -> None:
    run(waiting, 10)
    walk = one_step_walk(1)
    waiting.apply(walk)
    assert waiting.take_refusal() == (
        'refused AtlasSimInterfaceCommand behavior 4 (WALK) in USER: '
        'FAILED_TRANS_ILLEGAL_BEHAVIOR, WALK needs Stand: send STAND (behavior 0) first')
    assert waiting.take_refusal() is None
    assert waiting.state().behavior_feedback.status_flags == Status.FAILED_TRANS_ILLEGAL_BEHAVIOR
    waiting.apply(command(Behavior.STAND))  # the remedy: taken at once
    assert waiting.take_refusal() is None
    assert waiting.state().current_behavior == Behavior.STAND


def test_a_walk_without_its_first_step_outside_walk_is_said_aloud(
        interface: AtlasSimInterface) -> None:
    walk = one_step_walk(3)
    interface.apply(walk)
    assert interface.take_refusal() == (
        'ignored AtlasSimInterfaceCommand behavior 4 (WALK) in STAND: its step_queue has '
        'step_index [3], and a new walk starts with step_index 1')
    assert interface.current_behavior == Behavior.STAND


def test_a_walk_asked_for_while_stand_takes_over_waits_for_it(
        waiting: AtlasSimInterface) -> None:
    run(waiting, 1500)
    waiting.apply(command(Behavior.STAND))
    assert waiting.stand is not None and waiting.stand.taking_over
    walk = one_step_walk(1)
    waiting.apply(walk)  # DRCSim's actionlib server: STAND succeeded, then its WALK, once
    run(waiting, 1)
    state = waiting.state()
    assert (state.current_behavior, state.behavior_feedback.status_flags) == (
        Behavior.STAND, Status.TRANSITION_IN_PROGRESS)
    taken_at = None
    for k in range(1500):
        run(waiting, 1)
        if waiting.current_behavior == Behavior.WALK:
            taken_at = k
            break
    assert taken_at is not None
    assert 900 <= taken_at <= 1000  # the Stand's take-over: 1 s from the STAND
