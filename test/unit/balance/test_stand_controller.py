"""The estimator and the Stand controller on the Atlas model, against static cases: the
robot placed in DRCSim's Stand pose, at rest or with a known velocity."""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.balance import BalanceError, lipm, support
from tutorial_atlas_control.balance.estimator import BalanceEstimator
from tutorial_atlas_control.balance.manipulate import PelvisServo
from tutorial_atlas_control.balance.stand import StandController, StandReference, pitch_of
from tutorial_atlas_control.balance.stand_behaviour import StandBehaviour
from tutorial_atlas_control.balance.stand_pose import STAND_POSE_RAD, place_in_stand_pose
from tutorial_atlas_control.sim import model as atlas_model

SOLE_HALF_SIZE_M = (0.13, 0.0624435)


@pytest.fixture(scope='module')
def atlas() -> atlas_model.AtlasModel:
    return atlas_model.load_model()


@pytest.fixture
def placed(atlas: atlas_model.AtlasModel) -> mujoco.MjData:
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    return data


def test_the_stand_pose_stands_on_flat_soles(atlas: atlas_model.AtlasModel,
                                             placed: mujoco.MjData) -> None:
    state = BalanceEstimator(atlas).estimate(placed.qpos, placed.qvel)
    np.testing.assert_allclose(placed.qpos[atlas.qpos_adr], STAND_POSE_RAD)
    assert state.in_contact == (True, True)
    assert placed.qpos[atlas.free_qpos_adr + 2] == pytest.approx(0.911, abs=0.005)
    # Knees at 0.518 rad: the soles flat within 0.01 rad (their centres within 2 mm of
    # the ground, their heels touching), side by side.
    np.testing.assert_allclose(state.sole_centres[:, 2], 0.0, atol=2e-3)
    assert np.all(state.sole_rotations[:, 2, 2] > np.cos(0.01))
    extent = np.ptp(state.support_polygon, axis=0)
    np.testing.assert_allclose(extent, [0.26, 0.406], atol=2e-3)  # two soles 0.26 x 0.125
    assert support.inside(state.support_polygon, state.com[:2], 0.05)


def test_the_estimate_is_the_model_s(atlas: atlas_model.AtlasModel,
                                     placed: mujoco.MjData) -> None:
    """CoM and bias as mj_forward gives them; at rest the capture point is the CoM; moving
    the whole robot at v moves the CoM at v and the capture point by v / omega."""
    estimator = BalanceEstimator(atlas)
    state = estimator.estimate(placed.qpos, placed.qvel)
    mujoco.mj_forward(atlas.model, placed)
    np.testing.assert_allclose(state.com, placed.subtree_com[0])
    np.testing.assert_allclose(state.bias_nm, placed.qfrc_bias[atlas.dof_adr])
    assert estimator.mass_kg == pytest.approx(float(np.sum(atlas.model.body_mass)))
    np.testing.assert_allclose(state.capture_point, state.com[:2])
    moving = placed.qvel.copy()
    moving[0:3] = (0.3, -0.1, 0.0)
    state = estimator.estimate(placed.qpos, moving)
    np.testing.assert_allclose(state.com_velocity, (0.3, -0.1, 0.0), atol=1e-12)
    omega = lipm.natural_frequency(state.com[2])
    np.testing.assert_allclose(state.capture_point, state.com[:2] + np.array([0.3, -0.1]) / omega)


def test_a_soles_jacobian_gives_its_centres_rate(atlas: atlas_model.AtlasModel,
                                                 placed: mujoco.MjData) -> None:
    """The left knee bending: the left sole's jacobian times the knee's rate is its centre's
    finite difference; the right sole does not move."""
    estimator = BalanceEstimator(atlas)
    state = estimator.estimate(placed.qpos, placed.qvel)
    knee = 7  # l_leg_kny, tutorial order
    h = 1e-6
    moved = placed.qpos.copy()
    moved[atlas.qpos_adr[knee]] += 0.5 * h
    after = estimator.estimate(moved, placed.qvel)
    rate = state.sole_jacobians[:, :, knee] * 0.5
    np.testing.assert_allclose(rate[0, 0:3],
                               (after.sole_centres[0] - state.sole_centres[0]) / h, atol=1e-6)
    assert np.linalg.norm(rate[0, 0:3]) > 0.1
    np.testing.assert_allclose(rate[1], 0.0, atol=1e-12)


def test_at_rest_the_controller_holds_the_weight_by_statics(atlas: atlas_model.AtlasModel,
                                                            placed: mujoco.MjData) -> None:
    """Held where it is, the contact wrenches carry the weight; the torques are inverse
    statics: bias minus J^T lambda, so the floating base's equations balance with them."""
    estimator = BalanceEstimator(atlas)
    state = estimator.estimate(placed.qpos, placed.qvel)
    here = dataclasses.replace(StandReference.from_state(state),
                               capture_point=state.capture_point)
    controller = StandController(estimator.mass_kg, atlas.effort_limit_nm, here,
                                 SOLE_HALF_SIZE_M)
    out = controller.tick(state, placed.qpos[atlas.qpos_adr], placed.qvel[atlas.dof_adr])
    weight_n = estimator.mass_kg * lipm.GRAVITY_M_S2
    np.testing.assert_allclose(out.contact_wrenches[:, 0:3].sum(axis=0), [0, 0, weight_n],
                               atol=1e-6 * weight_n)
    np.testing.assert_allclose(out.desired_cop, state.com[:2], atol=1e-3)
    # Base rows: qfrc_bias = J_c^T lambda (the contact wrenches hold the robot still).
    mujoco.mj_forward(atlas.model, placed)
    generalized = placed.qfrc_bias.copy()
    jacp, jacr = np.zeros((3, atlas.model.nv)), np.zeros((3, atlas.model.nv))
    for foot, name in enumerate(('l_foot', 'r_foot')):
        body = mujoco.mj_name2id(atlas.model, mujoco.mjtObj.mjOBJ_BODY, name)
        mujoco.mj_jac(atlas.model, placed, jacp, jacr, state.sole_centres[foot], body)
        generalized -= np.vstack([jacp, jacr]).T @ out.contact_wrenches[foot]
    np.testing.assert_allclose(generalized[0:3], 0.0, atol=1e-6 * weight_n)
    np.testing.assert_allclose(generalized[3:6], 0.0, atol=2.0)
    # The knees carry the body: tens of N m, well inside their limits.
    assert 10.0 < abs(out.torque_nm[7]) < 60.0


def test_a_capture_point_ahead_moves_the_pressure_centre_further_ahead(
        atlas: atlas_model.AtlasModel, placed: mujoco.MjData) -> None:
    """Pushed forward, the law puts the pressure centre ahead of the capture point, but
    never beyond the soles (less the margin)."""
    estimator = BalanceEstimator(atlas)
    rest = estimator.estimate(placed.qpos, placed.qvel)
    controller = StandController(estimator.mass_kg, atlas.effort_limit_nm,
                                 StandReference.from_state(rest), SOLE_HALF_SIZE_M)
    for speed, beyond in ((0.1, False), (1.0, True)):
        moving = placed.qvel.copy()
        moving[0] = speed
        state = estimator.estimate(placed.qpos, moving)
        cop = controller.desired_cop(state)
        assert cop[0] > state.capture_point[0] or beyond
        reach = state.support_polygon[:, 0].max() - controller.gains.cop_margin_m
        assert cop[0] <= reach + 1e-9
        assert bool(cop[0] == pytest.approx(reach, abs=1e-4)) is beyond


def test_the_polygon_is_kept_while_the_feet_stay_and_redone_when_they_move(
        atlas: atlas_model.AtlasModel, placed: mujoco.MjData) -> None:
    estimator = BalanceEstimator(atlas)
    first = estimator.estimate(placed.qpos, placed.qvel).support_polygon
    assert estimator.estimate(placed.qpos, placed.qvel).support_polygon is first
    moved = placed.qpos.copy()
    moved[0] += 0.01  # the whole robot 1 cm forward
    again = estimator.estimate(moved, placed.qvel).support_polygon
    assert again is not first
    np.testing.assert_allclose(again, first + [0.01, 0.0])


def test_stand_behaviour_is_the_controller_held_where_it_started(
        atlas: atlas_model.AtlasModel, placed: mujoco.MjData) -> None:
    """The simulator's Stand behaviour: the controller's torque for the state in the
    MjData, with the reference taken at start(); asked before start(), an error."""
    behaviour = StandBehaviour(atlas)
    with pytest.raises(BalanceError, match='before start'):
        behaviour.torque(placed)
    behaviour.start(placed)
    estimator = BalanceEstimator(atlas)
    rest = estimator.estimate(placed.qpos, placed.qvel)
    assert behaviour.estimator.sole_half_size_m == pytest.approx(SOLE_HALF_SIZE_M)
    controller = StandController(estimator.mass_kg, atlas.effort_limit_nm,
                                 StandReference.from_state(rest), SOLE_HALF_SIZE_M)
    pushed = mujoco.MjData(atlas.model)
    pushed.qpos[:], pushed.qvel[:] = placed.qpos, placed.qvel
    pushed.qvel[0] = 0.2  # moving forward: the capture point ahead of where it started
    expected = controller.tick(estimator.estimate(pushed.qpos, pushed.qvel),
                               pushed.qpos[atlas.qpos_adr], pushed.qvel[atlas.dof_adr])
    np.testing.assert_array_equal(behaviour.torque(pushed), expected.torque_nm)
    assert behaviour.last_output is not None
    assert behaviour.last_output.desired_cop[0] > rest.capture_point[0] + 0.01


def _rotation_rate(before: np.ndarray, after: np.ndarray, seconds: float) -> np.ndarray:
    """The angular velocity (rad/s, world) that turns `before` into `after` in `seconds`."""
    turn = after @ before.T
    return 0.5 * np.array([turn[2, 1] - turn[1, 2], turn[0, 2] - turn[2, 0],
                           turn[1, 0] - turn[0, 1]]) / seconds


def test_a_moving_reference_carries_its_own_rates(atlas: atlas_model.AtlasModel,
                                                  placed: mujoco.MjData) -> None:
    """Manipulate's squat from the Stand pose down into the tipped range: the reference's
    rates are its time derivative (so the PDs damp about them), and zero once arrived."""
    behaviour = StandBehaviour(atlas)
    behaviour.start(placed)
    data = mujoco.MjData(atlas.model)
    data.qpos[:], data.qvel[:] = placed.qpos, placed.qvel

    def reference_at(time_s: float) -> StandReference:
        data.time = time_s
        behaviour.torque(data)
        assert behaviour.controller is not None
        return behaviour.controller.reference

    reference_at(1.5)  # the start's transition over: the reference on the squat table
    behaviour.servo(PelvisServo(0.76, yaw_rad=0.2), 1.5)
    h = 1e-4
    for time_s in (1.8, 2.0, 2.3):
        before, middle, after = (reference_at(time_s + d) for d in (-h, 0.0, h))
        assert middle.com_height_rate_m_s == pytest.approx(
            (after.com_height_m - before.com_height_m) / (2 * h), rel=1e-3, abs=1e-5)
        np.testing.assert_allclose(
            middle.pelvis_angular_velocity,
            _rotation_rate(before.pelvis_rotation, after.pelvis_rotation, 2 * h),
            rtol=1e-3, atol=1e-4)
        np.testing.assert_allclose(middle.posture_rate_rad_s,
                                   (after.posture_rad - before.posture_rad) / (2 * h),
                                   rtol=1e-3, atol=1e-4)
    assert reference_at(2.3).pelvis_angular_velocity[1] > 0.3  # leaning forward, fast
    arrived = reference_at(2.6)
    assert pitch_of(arrived.pelvis_rotation) == pytest.approx(
        behaviour.squats.pitch_for(0.76), abs=1e-12)
    assert arrived.com_height_rate_m_s == 0.0 and not arrived.posture_rate_rad_s.any()


def test_the_pds_damp_about_the_reference_s_rates(atlas: atlas_model.AtlasModel,
                                                   placed: mujoco.MjData) -> None:
    """A robot moving as its reference moves feels no damping: the height and orientation
    PDs act on the error alone."""
    estimator = BalanceEstimator(atlas)
    moving = placed.qvel.copy()
    moving[2], moving[4] = 0.1, 0.3  # rising, pitching (the free joint's local y)
    state = estimator.estimate(placed.qpos, moving)
    held = StandReference.from_state(state)
    following = dataclasses.replace(held, com_height_rate_m_s=float(state.com_velocity[2]),
                                    pelvis_angular_velocity=state.pelvis_angular_velocity)
    gains = StandController(estimator.mass_kg, atlas.effort_limit_nm, held,
                            SOLE_HALF_SIZE_M).gains
    for reference, damped in ((held, True), (following, False)):
        controller = StandController(estimator.mass_kg, atlas.effort_limit_nm, reference,
                                     SOLE_HALF_SIZE_M)
        force, moment = controller.centroidal_wrench(state, state.com[:2])
        weight_n = estimator.mass_kg * lipm.GRAVITY_M_S2
        drag = estimator.mass_kg * gains.height_kd * state.com_velocity[2]
        assert force[2] == pytest.approx(weight_n - drag if damped else weight_n)
        expected = (-gains.orientation_kd * state.pelvis_angular_velocity if damped
                    else np.zeros(3))
        np.testing.assert_allclose(moment, expected, atol=1e-9)
