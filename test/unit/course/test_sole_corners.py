"""The soles' corner spheres: a sole flat on the VRC course's heightfield bears on its corners.

MuJoCo collides a box with a heightfield one contact a prism, wherever its penetration search
ends; in the rubble's straight (the finals' falls at steps 91-97) a flat left sole bore on two
points 5 cm apart across its middle, and it tipped about them onto its toes as the other foot
lifted. The corner spheres touch heightfields only: on a plane the box's four corners are the
contacts, as before.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from support.vrc_world import WORLD_PATH
from tutorial_atlas_control.course import course_height_m
from tutorial_atlas_control.sim import model
from tutorial_atlas_control.walking import SOLE_HALF_LENGTH_M

#: Where a flat left sole bore on two points 5 cm apart (finals_rubble, seed 11, at 65.1 s):
#: its centre (m) and heading (rad).
RUBBLE_SOLE_XY = (6.344, 13.714)
RUBBLE_YAW_RAD = 1.629
#: How far the soles are pressed into the ground (m): a standing sole's sinking.
PRESS_M = 0.0004


def _corner_geoms(m: mujoco.MjModel) -> list[int]:
    return [g for g in range(m.ngeom) if (m.geom(g).name or '').startswith(('l_foot_sole_corner',
                                                                             'r_foot_sole_corner'))]


def _left_sole_bearing(m: mujoco.MjModel) -> np.ndarray:
    """The left foot's contact points (k, 2) in its sole's frame (along, across), with the
    robot upright, joints at zero, the left sole flat on the ground at RUBBLE_SOLE_XY."""
    data = mujoco.MjData(m)
    mujoco.mj_kinematics(m, data)
    sole = m.geom('l_foot_sole').id
    half_thickness = float(m.geom_size[sole][2])
    offset = data.geom_xpos[sole] - data.qpos[0:3]  # sole centre from the pelvis, unturned
    cos, sin = np.cos(RUBBLE_YAW_RAD), np.sin(RUBBLE_YAW_RAD)
    turned = np.array([cos * offset[0] - sin * offset[1], sin * offset[0] + cos * offset[1]])
    ground_m = course_height_m(*RUBBLE_SOLE_XY)
    data.qpos[0:2] = np.array(RUBBLE_SOLE_XY) - turned
    data.qpos[2] = ground_m + half_thickness - PRESS_M - offset[2]
    data.qpos[3:7] = (np.cos(RUBBLE_YAW_RAD / 2), 0.0, 0.0, np.sin(RUBBLE_YAW_RAD / 2))
    mujoco.mj_forward(m, data)
    foot = m.body('l_foot').id
    rotation = data.geom_xmat[sole].reshape(3, 3)
    points = [rotation.T @ (contact.pos - data.geom_xpos[sole])
              for contact in data.contact[:data.ncon]
              if foot in (m.geom_bodyid[contact.geom1], m.geom_bodyid[contact.geom2])]
    return np.array(points)[:, 0:2]


@pytest.fixture(scope='module')
def course_model() -> mujoco.MjModel:
    return model.load_model(WORLD_PATH).model


def test_a_flat_sole_on_the_heightfield_bears_at_its_four_corners(
        course_model: mujoco.MjModel) -> None:
    bearing = _left_sole_bearing(course_model)
    along, across = bearing[:, 0], bearing[:, 1]
    assert along.min() < -0.9 * SOLE_HALF_LENGTH_M and along.max() > 0.9 * SOLE_HALF_LENGTH_M
    assert across.min() < -0.05 and across.max() > 0.05


def test_without_the_corners_it_bears_on_a_few_points_in_its_middle(
        course_model: mujoco.MjModel) -> None:
    """The artefact the corners mend, so that the test above can fail."""
    bare = mujoco.MjModel.from_xml_path(str(WORLD_PATH))
    bare.geom_conaffinity[_corner_geoms(bare)] = 0
    along = _left_sole_bearing(bare)[:, 0]
    assert along.max() - along.min() < SOLE_HALF_LENGTH_M


def test_the_corners_touch_heightfields_only(course_model: mujoco.MjModel) -> None:
    corners = _corner_geoms(course_model)
    assert len(corners) == 8
    bit = int(course_model.geom_conaffinity[corners[0]])
    assert bit and all(int(course_model.geom_contype[g]) == 0 for g in corners)
    touched = [g for g in range(course_model.ngeom) if int(course_model.geom_contype[g]) & bit]
    assert touched and all(course_model.geom_type[g] == mujoco.mjtGeom.mjGEOM_HFIELD
                           for g in touched)
    atlas = model.load_model().model  # the plain world: its floor does not touch them
    assert not any(int(atlas.geom_contype[g]) & bit for g in range(atlas.ngeom))
