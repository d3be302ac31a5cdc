"""The estimator's copy of the model says at body level too that only the soles and the world
collide, so MuJoCo's broad phase sorts two robot bodies, not thirty: its contact list stays
the one the compiled body flags gave, row for row and bit for bit, on the flat world and
on the VRC course among its loose blocks."""

from __future__ import annotations

import copy

import mujoco
import numpy as np
import pytest

from support.vrc_world import WORLD_PATH
from tutorial_atlas_control.balance.estimator import CONTACT_HEIGHT_M, BalanceEstimator
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.ground import Ground

CONTACT_FIELDS = ('geom', 'dist', 'pos', 'frame')


def _contacts(model: mujoco.MjModel, qpos: np.ndarray) -> dict[str, np.ndarray]:
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    mujoco.mj_collision(model, data)
    return {name: getattr(data.contact, name)[:data.ncon].copy() for name in CONTACT_FIELDS}


def _placements(atlas: atlas_model.AtlasModel) -> list[np.ndarray]:
    """Standing on the world's ground, lifted within the contact height, one sole tipped
    up on its heel, and lifted clear."""
    data = mujoco.MjData(atlas.model)
    adr = atlas.free_qpos_adr
    ground_m = Ground(atlas.model).height_m(*atlas.model.qpos0[adr:adr + 2])
    place_in_stand_pose(atlas, data, ground_m=ground_m)
    standing = data.qpos.copy()
    placements = [standing]
    for lift_m in (0.5 * CONTACT_HEIGHT_M, 3.0 * CONTACT_HEIGHT_M):
        lifted = standing.copy()
        lifted[adr + 2] += lift_m
        placements.append(lifted)
    tipped = standing.copy()
    ankle = mujoco.mj_name2id(atlas.model, mujoco.mjtObj.mjOBJ_JOINT, 'l_leg_uay')
    tipped[atlas.model.jnt_qposadr[ankle]] -= 0.05
    placements.append(tipped)
    return placements


@pytest.mark.parametrize('world', ['atlas', 'vrc_task_2'])
def test_the_soles_contacts_are_those_of_the_compiled_body_flags(world: str) -> None:
    atlas = atlas_model.load_model() if world == 'atlas' else atlas_model.load_model(WORLD_PATH)
    estimator = BalanceEstimator(atlas)
    ours = estimator.model
    reference = copy.deepcopy(ours)  # the geoms switched off, the bodies as compiled
    reference.body_contype[:] = atlas.model.body_contype
    reference.body_conaffinity[:] = atlas.model.body_conaffinity
    soles = {int(ours.geom_bodyid[g]) for g in estimator._soles}
    robot = ours.body_rootid == atlas.pelvis_body_id
    assert {int(b) for b in np.flatnonzero(robot & (ours.body_contype != 0))} == soles
    assert not np.any(ours.body_conaffinity[robot])
    touching = 0
    for qpos in _placements(atlas):
        theirs, mine = _contacts(reference, qpos), _contacts(ours, qpos)
        for name in CONTACT_FIELDS:
            np.testing.assert_array_equal(mine[name], theirs[name], err_msg=name)
        touching += len(mine['dist']) > 0
    assert touching == 3  # all but the lift clear of the contact height
