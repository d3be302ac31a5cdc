"""The estimator's contacts come from MuJoCo's contact list: which sole touches which geom of
the world, where, with which normal; near contacts within CONTACT_HEIGHT_M count, and the
simulation's own model is left pushing only on real contact."""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.balance.estimator import CONTACT_HEIGHT_M, BalanceEstimator
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.sim import model as atlas_model

RAISED_M = 0.1


@pytest.fixture(scope='module')
def atlas() -> atlas_model.AtlasModel:
    return atlas_model.load_model()


def _placed(atlas: atlas_model.AtlasModel, lift_m: float = 0.0) -> mujoco.MjData:
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    data.qpos[atlas.free_qpos_adr + 2] += lift_m
    mujoco.mj_kinematics(atlas.model, data)
    return data


def _geom(model: mujoco.MjModel, name: str) -> int:
    return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)


def test_standing_soles_touch_the_floor_at_their_corners(atlas: atlas_model.AtlasModel) -> None:
    data = _placed(atlas)
    state = BalanceEstimator(atlas).estimate(data.qpos, data.qvel)
    assert state.in_contact == (True, True)
    floor = _geom(atlas.model, 'floor')
    for foot, contacts in enumerate(state.sole_contacts):
        assert len(contacts.points) == 4  # a box on a plane: its four bottom corners
        assert set(contacts.surface_geoms.tolist()) == {floor}
        np.testing.assert_allclose(contacts.normals, np.tile([0.0, 0.0, 1.0], (4, 1)),
                                   atol=1e-12)
        # The Stand pose's soles tilt about a millimetre; MuJoCo puts a point halfway.
        np.testing.assert_allclose(contacts.points[:, 2], 0.0, atol=1.5e-3)
        assert float(np.min(contacts.distances_m)) < 1e-4
        centre = state.sole_centres[foot]
        np.testing.assert_allclose(contacts.points[:, :2].mean(axis=0), centre[:2], atol=1e-9)
    lowest = min(float(np.min(c.distances_m)) for c in state.sole_contacts)
    assert lowest == pytest.approx(0.0, abs=1e-9)  # placed: the lowest corner on the floor


@pytest.mark.parametrize(('lift_m', 'touching'), [
    (0.5 * CONTACT_HEIGHT_M, True), (2.0 * CONTACT_HEIGHT_M, False)])
def test_a_lifted_robot_touches_only_within_the_contact_height(
        atlas: atlas_model.AtlasModel, lift_m: float, touching: bool) -> None:
    data = _placed(atlas, lift_m)
    state = BalanceEstimator(atlas).estimate(data.qpos, data.qvel)
    assert state.in_contact == (touching, touching)
    distances = np.concatenate([c.distances_m for c in state.sole_contacts])
    if touching:  # the lowest corner at the lift, the others within the soles' tilt
        assert float(np.min(distances)) == pytest.approx(lift_m, abs=1e-9)
        assert float(np.max(distances)) < lift_m + 3e-3


def test_the_simulations_model_keeps_its_own_margins(atlas: atlas_model.AtlasModel) -> None:
    """A hovering robot gets no contact force: the wide margin is the estimator's copy's."""
    margins = atlas.model.geom_margin.copy()
    BalanceEstimator(atlas)
    np.testing.assert_array_equal(atlas.model.geom_margin, margins)
    data = _placed(atlas, 0.5 * CONTACT_HEIGHT_M)
    mujoco.mj_forward(atlas.model, data)
    assert data.nefc == 0


def test_a_sole_on_a_block_touches_the_block_not_the_floor(
        atlas: atlas_model.AtlasModel) -> None:
    """The world decides what a sole stands on: the left foot on a block, the right in the air
    above the floor."""
    data = _placed(atlas, RAISED_M)
    left_centre = data.geom_xpos[_geom(atlas.model, 'l_foot_sole')]
    spec = mujoco.MjSpec.from_file(str(atlas.path))
    spec.worldbody.add_geom(name='block', type=mujoco.mjtGeom.mjGEOM_BOX,
                            size=[0.2, 0.08, RAISED_M / 2],
                            pos=[left_centre[0], left_centre[1] + 0.02, RAISED_M / 2])
    on_block = dataclasses.replace(atlas, model=spec.compile())
    state = BalanceEstimator(on_block).estimate(data.qpos, data.qvel)
    assert state.in_contact == (True, False)
    left = state.sole_contacts[0]
    assert set(left.surface_geoms.tolist()) == {_geom(on_block.model, 'block')}
    np.testing.assert_allclose(left.points[:, 2], RAISED_M, atol=1.5e-3)
    np.testing.assert_allclose(left.normals[:, 2], 1.0, atol=1e-12)
