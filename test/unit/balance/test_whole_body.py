"""The whole-body layer's tasks and constraints, each alone, and the layer over the Atlas model
placed in DRCSim's Stand pose: the tasks' wrench is what the soles press, the posture task
adds its PD, the limits clip."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.balance import lipm
from tutorial_atlas_control.balance.estimator import BalanceEstimator, BalanceState
from tutorial_atlas_control.balance.stand import yaw_rotation
from tutorial_atlas_control.balance.stand_pose import STAND_POSE_RAD, place_in_stand_pose
from tutorial_atlas_control.balance.whole_body import (
    CapturePointTask,
    ComHeightTask,
    ContactConstraint,
    PelvisOrientationTask,
    PostureTask,
    WholeBodyLayer,
)
from tutorial_atlas_control.sim import model as atlas_model

MASS_KG = 90.0


@pytest.fixture(scope='module')
def atlas() -> atlas_model.AtlasModel:
    return atlas_model.load_model()


@pytest.fixture(scope='module')
def standing(atlas: atlas_model.AtlasModel) -> tuple[BalanceState, mujoco.MjData]:
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    return BalanceEstimator(atlas).estimate(data.qpos, data.qvel), data


def test_the_capture_point_task_pushes_the_com_away_from_the_pressure_centre(
        standing: tuple[BalanceState, mujoco.MjData]) -> None:
    state, _ = standing
    cop = state.com[:2] + np.array([0.02, -0.01])
    force, moment = CapturePointTask(cop).wrench(state, MASS_KG)
    expected = MASS_KG * lipm.com_acceleration(state.com[:2], cop, state.omega)
    np.testing.assert_allclose(force[0:2], expected, rtol=1e-12)
    assert force[2] == 0.0 and tuple(moment) == (0.0, 0.0, 0.0)


def test_the_height_task_carries_the_weight_and_pulls_towards_its_height(
        standing: tuple[BalanceState, mujoco.MjData]) -> None:
    state, _ = standing
    height = float(state.com[2])
    at, _ = ComHeightTask(height, 0.0, 400.0, 40.0).wrench(state, MASS_KG)
    assert at[2] == pytest.approx(MASS_KG * lipm.GRAVITY_M_S2, rel=1e-12)
    up, _ = ComHeightTask(height + 0.01, 0.0, 400.0, 40.0).wrench(state, MASS_KG)
    assert up[2] - at[2] == pytest.approx(MASS_KG * 400.0 * 0.01, rel=1e-9)
    assert (up[0], up[1]) == (0.0, 0.0)


def test_the_orientation_task_turns_the_pelvis_towards_its_frame(
        standing: tuple[BalanceState, mujoco.MjData]) -> None:
    state, _ = standing
    turned = yaw_rotation(0.01) @ state.pelvis_rotation
    force, moment = PelvisOrientationTask(turned, np.zeros(3), 3000.0, 300.0).wrench(
        state, MASS_KG)
    assert tuple(force) == (0.0, 0.0, 0.0)
    assert moment[2] == pytest.approx(3000.0 * math.sin(0.01), rel=1e-3)
    assert abs(moment[0]) < 1.0 and abs(moment[1]) < 1.0


def test_the_posture_task_is_a_joint_pd() -> None:
    kp, kd = np.full(28, 100.0), np.full(28, 2.0)
    task = PostureTask(STAND_POSE_RAD, np.zeros(28), kp, kd)
    q = STAND_POSE_RAD + 0.01
    qd = np.full(28, 0.5)
    np.testing.assert_allclose(task(None, q, qd), -1.0 - 1.0, rtol=1e-12)  # type: ignore[arg-type]


def test_a_contact_keeps_its_force_within_friction_about_the_sole_normal() -> None:
    upright = np.eye(3)
    contact = ContactConstraint(True, 0.13, 0.06, friction=0.5)
    wrench = np.array([300.0, -400.0, 600.0, 0.0, 0.0, 0.0])
    made = contact.feasible(wrench, upright)
    assert made[2] == 600.0
    assert math.hypot(made[0], made[1]) == pytest.approx(300.0, rel=1e-12)  # 0.5 * 600 N
    np.testing.assert_allclose(made[0:2] / np.linalg.norm(made[0:2]), [0.6, -0.8])
    within = np.array([100.0, 0.0, 600.0, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(contact.feasible(within, upright), within)
    pulling = contact.feasible(np.array([10.0, 0.0, -50.0, 0.0, 0.0, 0.0]), upright)
    np.testing.assert_array_equal(pulling[[0, 1, 2]], [0.0, 0.0, 0.0])  # no pull, no friction


def test_a_contact_keeps_its_pressure_centre_on_the_sole() -> None:
    contact = ContactConstraint(True, 0.13, 0.06)
    made = contact.feasible(np.array([0.0, 0.0, 500.0, 100.0, -200.0, 5.0]), np.eye(3))
    np.testing.assert_allclose(made[3:6], [500.0 * 0.06, -500.0 * 0.13, 5.0])


def test_the_soles_press_the_tasks_wrench_and_the_posture_adds_its_pd(
        atlas: atlas_model.AtlasModel, standing: tuple[BalanceState, mujoco.MjData]) -> None:
    state, data = standing
    layer = WholeBodyLayer(MASS_KG, atlas.effort_limit_nm)
    tasks = [CapturePointTask(state.com[:2]),
             ComHeightTask(float(state.com[2]), 0.0, 400.0, 40.0),
             PelvisOrientationTask(state.pelvis_rotation, np.zeros(3), 3000.0, 300.0)]
    contacts = (ContactConstraint(True, 0.13, 0.0624, friction=1.0),) * 2
    q, qd = data.qpos[atlas.qpos_adr], data.qvel[atlas.dof_adr]
    bare = layer.solve(state, tasks, contacts, (), q, qd)
    np.testing.assert_allclose(bare.contact_wrenches[:, 0:3].sum(axis=0),
                               [0.0, 0.0, MASS_KG * lipm.GRAVITY_M_S2], atol=1e-9)
    kp = np.full(28, 10.0)
    posture = PostureTask(q + 0.1, np.zeros(28), kp, np.zeros(28))
    with_posture = layer.solve(state, tasks, contacts, (posture,), q, qd)
    np.testing.assert_allclose(with_posture.torque_nm - bare.torque_nm, 1.0, rtol=1e-9)
    lifted = (ContactConstraint(True, 0.13, 0.0624), ContactConstraint(False, 0.13, 0.0624))
    one_foot = layer.solve(state, tasks, lifted, (), q, qd)
    np.testing.assert_array_equal(one_foot.contact_wrenches[1], np.zeros(6))
    big = np.full(28, 1e6)
    np.testing.assert_array_equal(layer.limit(big.copy()), atlas.effort_limit_nm)
