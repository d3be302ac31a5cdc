"""The whole-body layer's QP solver (contact_qp): on flat ground it gives inverse statics'
wrenches where those are feasible; where one sole cannot carry its share, the other does,
within every constraint (friction pyramid, pressure centre on each sole, torque limits)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.balance import contact_wrench
from tutorial_atlas_control.balance.contact_qp import contact_frame, solve_contact_qp
from tutorial_atlas_control.balance.errors import BalanceError
from tutorial_atlas_control.balance.estimator import BalanceEstimator, BalanceState
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.balance.whole_body import (
    INVERSE_STATICS,
    QP,
    CapturePointTask,
    ComHeightTask,
    ContactConstraint,
    PelvisOrientationTask,
    PostureTask,
    WholeBodyLayer,
    ground_normal,
)
from tutorial_atlas_control.sim import model as atlas_model

MASS_KG = 90.0
HALF_LENGTH_M, HALF_WIDTH_M, FRICTION = 0.13, 0.0624, 1.0


@pytest.fixture(scope='module')
def atlas() -> atlas_model.AtlasModel:
    return atlas_model.load_model()


@pytest.fixture(scope='module')
def standing(atlas: atlas_model.AtlasModel) -> tuple[BalanceState, mujoco.MjData]:
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    return BalanceEstimator(atlas).estimate(data.qpos, data.qvel), data


def _tasks(state: BalanceState, cop_offset_m: tuple[float, float]) -> list:
    return [CapturePointTask(state.com[:2] + np.array(cop_offset_m)),
            ComHeightTask(float(state.com[2]), 0.0, 400.0, 40.0),
            PelvisOrientationTask(state.pelvis_rotation, np.zeros(3), 3000.0, 300.0)]


def _made(wrenches: np.ndarray, centres: np.ndarray, com: np.ndarray) -> np.ndarray:
    """The wrench [force, moment about com] the soles' wrenches make."""
    force = wrenches[:, 0:3].sum(axis=0)
    moment = wrenches[:, 3:6].sum(axis=0) + sum(
        np.cross(centres[foot] - com, wrenches[foot, 0:3]) for foot in (0, 1))
    return np.concatenate([force, moment])


def _assert_feasible(wrench: np.ndarray, frame: np.ndarray) -> None:
    """Within the sole's constraints (a micronewton's slack for the solver)."""
    (ft1, ft2, fn), (mt1, mt2, _) = frame @ wrench[0:3], frame @ wrench[3:6]
    slack = 1e-6
    assert fn >= -slack
    mu = FRICTION / math.sqrt(2.0)
    assert abs(ft1) <= mu * fn + slack and abs(ft2) <= mu * fn + slack
    assert abs(mt1) <= HALF_WIDTH_M * fn + slack
    assert abs(mt2) <= HALF_LENGTH_M * fn + slack


@pytest.mark.parametrize('cop_offset_m', [(0.0, 0.0), (0.03, 0.0), (-0.02, 0.05)])
def test_on_flat_ground_the_qp_gives_inverse_statics_wrenches_where_they_are_feasible(
        atlas: atlas_model.AtlasModel, standing: tuple[BalanceState, mujoco.MjData],
        cop_offset_m: tuple[float, float]) -> None:
    state, data = standing
    q, qd = data.qpos[atlas.qpos_adr], data.qvel[atlas.dof_adr]
    contacts = (ContactConstraint(True, HALF_LENGTH_M, HALF_WIDTH_M, friction=FRICTION),) * 2
    posture = PostureTask(q + 0.05, np.zeros(28), np.full(28, 10.0), np.zeros(28))
    tasks = _tasks(state, cop_offset_m)
    solved = {name: WholeBodyLayer(MASS_KG, atlas.effort_limit_nm, name).solve(
        state, tasks, contacts, (posture,), q, qd) for name in (INVERSE_STATICS, QP)}
    np.testing.assert_allclose(solved[QP].contact_wrenches,
                               solved[INVERSE_STATICS].contact_wrenches, atol=1e-3)
    np.testing.assert_allclose(solved[QP].torque_nm, solved[INVERSE_STATICS].torque_nm,
                               atol=1e-3)


def test_where_one_sole_cannot_carry_its_moment_the_other_does(
        standing: tuple[BalanceState, mujoco.MjData]) -> None:
    """A split that asks the left sole for a pitch moment beyond its toe: inverse statics
    clamps it and loses 25 N m; the QP moves it to the right sole and makes the whole
    wrench (but for the 1 % its tie-break with the split costs), each sole within its
    constraints."""
    state, _ = standing
    com, centres = state.com, state.sole_centres
    split = np.zeros((2, 6))
    split[:, 2] = 0.5 * MASS_KG * 9.81
    split[0, 4] = HALF_LENGTH_M * split[0, 2] + 25.0  # 25 N m beyond the left toe
    wanted = _made(split, centres, com)
    clamped = np.array([contact_wrench.make_feasible(split[foot], state.sole_rotations[foot],
                                                     HALF_LENGTH_M, HALF_WIDTH_M,
                                                     friction=FRICTION) for foot in (0, 1)])
    assert np.linalg.norm(_made(clamped, centres, com) - wanted) > 24.0
    frames = [contact_frame(ground_normal(state, foot), state.sole_rotations[foot])
              for foot in (0, 1)]
    solved = solve_contact_qp(wanted, split, com, centres, frames,
                              (HALF_LENGTH_M, HALF_WIDTH_M, None, FRICTION),
                              state.sole_jacobians, state.bias_nm, np.full(28, 1e4))
    assert solved is not None
    made = _made(solved, centres, com)
    np.testing.assert_allclose(made[0:3], wanted[0:3], atol=0.01)
    np.testing.assert_allclose(made[3:6], wanted[3:6], atol=0.5)
    for foot in (0, 1):
        _assert_feasible(solved[foot], frames[foot])


def test_the_qp_keeps_the_joint_torques_within_their_limits(
        atlas: atlas_model.AtlasModel, standing: tuple[BalanceState, mujoco.MjData]) -> None:
    """Leg limits at 60 % of what inverse statics' torques need: the QP's torques stay
    within them (giving up some of the wrench), inverse statics' do not."""
    state, data = standing
    q, qd = data.qpos[atlas.qpos_adr], data.qvel[atlas.dof_adr]
    contacts = (ContactConstraint(True, HALF_LENGTH_M, HALF_WIDTH_M, friction=FRICTION),) * 2
    tasks = _tasks(state, (0.02, 0.0))
    free = WholeBodyLayer(MASS_KG, np.full(28, 1e4)).solve(state, tasks, contacts, (), q, qd)
    limits = np.maximum(0.6 * np.abs(free.torque_nm), np.abs(state.bias_nm) + 1.0)
    layer = WholeBodyLayer(MASS_KG, limits, QP)
    solved = layer.solve(state, tasks, contacts, (), q, qd)
    assert layer.qp_fallbacks == 0
    assert np.any(np.abs(free.torque_nm) > limits + 1.0)
    assert np.all(np.abs(solved.torque_nm) <= limits + 1e-6)
    for foot in (0, 1):
        _assert_feasible(solved.contact_wrenches[foot], contact_frame(
            ground_normal(state, foot), state.sole_rotations[foot]))


def test_the_contact_frame_lays_the_sole_on_the_ground() -> None:
    slope = math.radians(16.0)
    normal = np.array([-math.sin(slope), 0.0, math.cos(slope)])
    frame = contact_frame(normal, np.eye(3))
    np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(frame[2], normal)
    np.testing.assert_allclose(frame[0], [math.cos(slope), 0.0, math.sin(slope)], atol=1e-12)


def test_an_unknown_solver_is_refused(atlas: atlas_model.AtlasModel) -> None:
    with pytest.raises(BalanceError, match="whole-body solver 'newton' is not one of"):
        WholeBodyLayer(MASS_KG, atlas.effort_limit_nm, 'newton')
