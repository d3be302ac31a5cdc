"""The Stand pose carried to a stance: with the feet side by side as the Stand pose puts
them it is the Stand pose itself, bit for bit; staggered or turned, the solved legs put each
sole flat where it lies with the pelvis upright over the soles' midpoint, lowered only where
a long stride leaves the legs short of the ground."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.balance import STAND_POSE_RAD, place_in_stand_pose
from tutorial_atlas_control.balance.sole import SOLE_GEOMS, sole_corners
from tutorial_atlas_control.balance.stance_posture import Stance, StancePosture
from tutorial_atlas_control.joints import JOINT_INDEX
from tutorial_atlas_control.sim import AtlasModel, load_model


@pytest.fixture(scope='module')
def atlas() -> AtlasModel:
    return load_model()


@pytest.fixture(scope='module')
def solver(atlas: AtlasModel) -> StancePosture:
    return StancePosture(atlas)


def _soles(atlas: AtlasModel, data: mujoco.MjData) -> tuple[np.ndarray, tuple[float, float]]:
    """(bottom-face centres (2, 3), yaws) of the soles, from their corners."""
    corners = [sole_corners(atlas.model, data, name) for name in SOLE_GEOMS]
    centres = np.array([c.mean(axis=0) for c in corners])
    yaws = tuple(math.atan2(c[0, 1] - c[3, 1], c[0, 0] - c[3, 0]) for c in corners)
    return centres, (yaws[0], yaws[1])


def _flat(*yaws_rad: float) -> np.ndarray:
    """(n, 3, 3) the frames of soles lying flat at these headings."""
    return np.array([[[math.cos(y), -math.sin(y), 0.0], [math.sin(y), math.cos(y), 0.0],
                      [0.0, 0.0, 1.0]] for y in yaws_rad])


def _sole_frames(atlas: AtlasModel, data: mujoco.MjData) -> np.ndarray:
    """(2, 3, 3) the soles' frames, world."""
    geoms = [mujoco.mj_name2id(atlas.model, mujoco.mjtObj.mjOBJ_GEOM, n) for n in SOLE_GEOMS]
    return data.geom_xmat[geoms].reshape(2, 3, 3).copy()


def _placed(atlas: AtlasModel, solver: StancePosture, centres: np.ndarray,
            pelvis_yaw_rad: float, stance: Stance) -> mujoco.MjData:
    """The robot in `stance`'s posture, the pelvis upright at `pelvis_yaw_rad`, where the
    Stand pose holds it over the soles' midpoint, lowered as the stance says."""
    data = mujoco.MjData(atlas.model)
    c, s = math.cos(pelvis_yaw_rad), math.sin(pelvis_yaw_rad)
    heading = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    adr = atlas.free_qpos_adr
    data.qpos[adr:adr + 3] = centres.mean(axis=0) + heading @ solver.pelvis_offset_m
    data.qpos[adr + 2] -= stance.pelvis_lowered_m
    data.qpos[adr + 3:adr + 7] = (math.cos(pelvis_yaw_rad / 2), 0.0, 0.0,
                                  math.sin(pelvis_yaw_rad / 2))
    data.qpos[atlas.qpos_adr] = stance.posture_rad
    mujoco.mj_kinematics(atlas.model, data)
    return data


def test_feet_as_the_stand_pose_puts_them_keep_the_stand_pose(
        atlas: AtlasModel, solver: StancePosture) -> None:
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    centres, _ = _soles(atlas, data)
    stance = solver.stance(centres, _sole_frames(atlas, data), 0.0)
    assert stance.reached
    assert stance.posture_rad.tobytes() == STAND_POSE_RAD.tobytes()
    assert stance.pelvis_lowered_m == 0.0 and stance.com_lowered_m == 0.0


#: Stances a walk or a step leaves: the left foot's lead (m) and turn (rad), the right's turn.
STANCES = {'staggered 0.2 m': (-0.2, 0.0, 0.0), 'staggered 0.4 m': (0.4, 0.0, 0.0),
           'right behind 0.25 m, turned': (0.25, -0.06, 0.01), 'turned 0.3 rad': (0.0, 0.3, 0.0)}


@pytest.mark.parametrize('name', sorted(STANCES))
def test_a_stance_is_solved_with_each_sole_flat_where_it_lies(
        atlas: AtlasModel, solver: StancePosture, name: str) -> None:
    lead, left_yaw, right_yaw = STANCES[name]
    centres = np.array([[0.5 + lead / 2, 0.12, 0.0], [0.5 - lead / 2, -0.12, 0.0]])
    pelvis_yaw = 0.5 * (left_yaw + right_yaw)
    stance = solver.stance(centres, _flat(left_yaw, right_yaw), pelvis_yaw)
    assert stance.reached
    data = _placed(atlas, solver, centres, pelvis_yaw, stance)
    soles, yaws = _soles(atlas, data)
    np.testing.assert_allclose(soles, centres, atol=1e-6)
    np.testing.assert_allclose(yaws, (left_yaw, right_yaw), atol=1e-6)
    for name_ in SOLE_GEOMS:  # flat: every corner on the ground
        np.testing.assert_allclose(sole_corners(atlas.model, data, name_)[:, 2], 0.0,
                                   atol=1e-6)
    within = (atlas.lower_rad <= stance.posture_rad) & (stance.posture_rad <= atlas.upper_rad)
    assert within.all()


def test_a_long_stride_lowers_the_pelvis_until_the_legs_reach(
        atlas: AtlasModel, solver: StancePosture) -> None:
    """0.4 m apart fore and aft, the trailing leg is short of the ground at the Stand
    pose's height (its knee would have to straighten past its limit): the pelvis and the
    centre of mass come down a few centimetres; 0.2 m apart, a few millimetres at most."""
    far = solver.stance(np.array([[0.7, 0.12, 0.0], [0.3, -0.12, 0.0]]), _flat(0.0, 0.0), 0.0)
    near = solver.stance(np.array([[0.6, 0.12, 0.0], [0.4, -0.12, 0.0]]), _flat(0.0, 0.0), 0.0)
    assert 0.01 < far.pelvis_lowered_m < 0.06
    assert 0.0 < far.com_lowered_m < far.pelvis_lowered_m
    assert near.pelvis_lowered_m <= 0.005


def test_a_turned_foot_is_turned_at_its_hip(atlas: AtlasModel, solver: StancePosture) -> None:
    """The Stand pose's hip yaw is 0: the Stand's posture PD pulled a turned foot's hip back
    with 300 N m/rad, a torsion the sole carried."""
    stance = solver.stance(np.array([[0.0, 0.14, 0.0], [0.0, -0.12, 0.0]]), _flat(0.3, 0.0),
                           0.15)
    hips = stance.posture_rad[[JOINT_INDEX['l_leg_uhz'], JOINT_INDEX['r_leg_uhz']]]
    np.testing.assert_allclose(hips, (0.15, -0.15), atol=0.02)
