"""sim/vrc_task_2.xml: the course where course/ puts it, the terrain as Gazebo scaled
DRCSim's heightmap, friction as ODE combined it, and the VRC's robot."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from support.model_table import load_table
from support.vrc_world import WORLD_PATH, load_generator
from tutorial_atlas_control.course import vrc_task_2 as course
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.sim import model
from tutorial_atlas_control.sim.ground import Ground
from tutorial_atlas_control.sim.urdf import matching_urdf, read_joints

WORLD = load_generator()
TABLE = load_table()
CELL_M = 100 / 512

#: Heightmap vertices (image row from the top, column from the left) and their heights (m),
#: computed once from DRCSim's heightmap.png with Gazebo's scaling, -0.6 + 3.5 grey / 250.
PROBES: dict[str, tuple[int, int, float]] = {
    'pen': (440, 241, 0.030),
    'flat before gate_1': (399, 256, 0.030),
    'pit ramp south': (360, 259, -0.376),
    'pit ramp north': (326, 259, -0.558),
    'after the pit': (320, 256, -0.180),
    'uneven corridor': (266, 271, 0.212),
    'hill beside gate_3': (256, 287, 0.268),
    'before gate_3': (236, 282, 0.100),
    'rubble field edge': (195, 307, 0.282),
    'high hill': (205, 102, 1.262),
    'east flat': (410, 358, 0.030),
    'past gate_4': (143, 287, 0.030),
}
#: The pit's floor vertex (heightmap -0.6): there the ground is mud_ground_plane.
PIT_FLOOR = (343, 259)


def vertex_xy(row: int, column: int) -> tuple[float, float]:
    return -50 + column * CELL_M, 50 - row * CELL_M


@pytest.fixture(scope='module')
def atlas() -> model.AtlasModel:
    return model.load_model(WORLD_PATH)


@pytest.fixture(scope='module')
def placed(atlas: model.AtlasModel) -> mujoco.MjData:
    data = mujoco.MjData(atlas.model)
    mujoco.mj_forward(atlas.model, data)
    return data


def test_world_file_is_what_the_generator_writes() -> None:
    terrain = WORLD.load_terrain(WORLD_PATH.parent / WORLD.TERRAIN_FILE)
    assert WORLD_PATH.read_text() == WORLD.build(terrain), \
        'sim/vrc_task_2.xml is stale: run `python3 tools/make_vrc_world.py`'
    assert WORLD_PATH.with_suffix('.urdf').read_text() == WORLD.build_urdf(), \
        'sim/vrc_task_2.urdf is stale: run `python3 tools/make_vrc_world.py`'


def test_urdf_matches_the_robot_not_the_blocks(atlas: model.AtlasModel) -> None:
    """/tf and rviz get the VRC robot: its hands' links on fixed joints, the Hokuyo's
    (a body welded to the head in the model) on the spun hokuyo_joint as the simulator
    publishes it, each link once, the course's loose blocks (bodies of the world, not of
    the robot) left out."""
    path, text = matching_urdf(WORLD_PATH, atlas.model)
    links, joints = read_joints(text, str(path))
    assert {'l_palm', 'r_f3', 'hokuyo_link'} <= set(links)
    assert not any(link.startswith('cinder_block') for link in links)
    assert {joint.name: joint.kind for joint in joints}['hokuyo_joint'] == 'continuous'
    assert len(links) == len(set(links))


def test_terrain_heights_are_the_heightmap_scaled_as_gazebo_did(
        atlas: model.AtlasModel) -> None:
    ground = Ground(atlas.model)
    for name, (row, column, expected_m) in PROBES.items():
        assert ground.height_m(*vertex_xy(row, column)) == pytest.approx(expected_m, abs=0.02), \
            name
    assert ground.height_m(*vertex_xy(*PIT_FLOOR)) == pytest.approx(course.MUD_FLOOR_Z_M,
                                                                   abs=1e-9)


def test_heightfield_keeps_the_images_grey_levels_top_row_north(
        atlas: model.AtlasModel) -> None:
    m = atlas.model
    grey = WORLD.load_terrain(WORLD_PATH.parent / WORLD.TERRAIN_FILE).astype(float)
    field = m.hfield_data.reshape(m.hfield_nrow[0], m.hfield_ncol[0])
    # MuJoCo's row 0 is -y: the image's bottom row. Normalised by the brightest, 250.
    np.testing.assert_allclose(field[::-1], grey / course.HEIGHTMAP.brightest, atol=1e-6)
    np.testing.assert_allclose(m.hfield_size[0], (50, 50, 3.5, WORLD.TERRAIN_BASE_M))
    assert m.geom('terrain').pos[2] == pytest.approx(-0.6)


def test_no_floor_plane_but_the_pits(atlas: model.AtlasModel) -> None:
    m = atlas.model
    planes = [m.geom(g).name for g in range(m.ngeom)
              if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_PLANE]
    assert planes == ['mud_ground_plane']
    assert m.geom('mud_ground_plane').pos[2] == pytest.approx(course.MUD_FLOOR_Z_M)


def test_gates_posts_and_bars_where_the_course_says(atlas: model.AtlasModel,
                                                    placed: mujoco.MjData) -> None:
    for gate in course.GATES:
        across = np.array([-math.sin(gate.yaw_rad), math.cos(gate.yaw_rad)])
        for side, sign in (('left', 1), ('right', -1)):
            post = placed.geom(f'{gate.name}_{side}')
            np.testing.assert_allclose(post.xpos[:2], np.array([gate.x_m, gate.y_m])
                                       + sign * 2.5 * across, atol=1e-6, err_msg=gate.name)
            assert post.xpos[2] == pytest.approx(2.0)
        top = atlas.model.geom(f'{gate.name}_top')
        assert 2 * top.size[1] == pytest.approx(course.GATE_WIDTH_M)
        assert placed.geom(f'{gate.name}_top').xpos[2] == pytest.approx(4.1)


def test_mud_box_is_the_course_box_touching_nothing(atlas: model.AtlasModel) -> None:
    mud = atlas.model.geom('mud_atlas')
    np.testing.assert_allclose(mud.pos, course.MUD_BOX.centre_m)
    np.testing.assert_allclose(2 * mud.size, course.MUD_BOX.size_m)
    assert (mud.contype[0], mud.conaffinity[0]) == (0, 0)
    groups = {int(atlas.model.geom_group[g]) for g in range(atlas.model.ngeom)
              if g != mud.id}
    assert int(mud.group[0]) not in groups
    assert mud.id not in Ground(atlas.model).geom_ids


def test_blocks_loose_hollow_5_kg_where_the_world_file_put_them(
        atlas: model.AtlasModel, placed: mujoco.MjData) -> None:
    m = atlas.model
    assert len(course.BLOCKS) == 30
    block_geoms = set()
    for block in course.BLOCKS:
        body = m.body(block.name)
        assert body.mass[0] == pytest.approx(course.BLOCK_MASS_KG)
        assert m.jnt_type[body.jntadr[0]] == mujoco.mjtJoint.mjJNT_FREE
        geoms = [g for g in range(m.ngeom) if m.geom_bodyid[g] == body.id]
        assert len(geoms) == 5
        block_geoms.update(geoms)
        # Inside the envelope, hollow: the walls fill less than half of it.
        half = np.array(course.BLOCK_ENVELOPE_M) / 2
        for g in geoms:
            local = m.geom_pos[g] - (0, 0, half[2])
            assert np.all(np.abs(local) + m.geom_size[g] <= half + 1e-3), block.name
        volume = sum(np.prod(2 * m.geom_size[g]) for g in geoms)
        assert volume < 0.5 * np.prod(course.BLOCK_ENVELOPE_M)
        np.testing.assert_allclose(placed.body(block.name).xpos[:2], (block.x_m, block.y_m),
                                   atol=1e-6)
        assert placed.body(block.name).xpos[2] >= block.z_m  # raised, never lowered
    # Nothing starts inside the ground or another block ...
    for contact in placed.contact[:placed.ncon]:
        if block_geoms & set(contact.geom.tolist()):
            assert contact.dist > -1e-3
    # ... and a second later each block has settled near where DRCSim put it, at rest.
    data = mujoco.MjData(m)
    data.qpos[:] = placed.qpos
    data.eq_active[atlas.pin_eq_id] = 1
    for _ in range(1500):
        mujoco.mj_step(m, data)
    for block in course.BLOCKS:
        body = data.body(block.name)
        assert np.linalg.norm(body.xpos[:2] - (block.x_m, block.y_m)) < 0.1, block.name
        assert np.linalg.norm(body.cvel) < 1e-3, block.name


def contact_frictions(m: mujoco.MjModel, d: mujoco.MjData, sole: str) -> set[tuple]:
    """(other geom, friction (5,), condim) of the named sole's contacts."""
    sole_id = m.geom(sole).id
    found = set()
    for contact in d.contact[:d.ncon]:
        if sole_id in contact.geom:
            other = int(contact.geom[0] if contact.geom[1] == sole_id else contact.geom[1])
            found.add((m.geom(other).name, tuple(np.round(contact.friction, 6)),
                       int(contact.dim)))
    return found


def stand_at(atlas: model.AtlasModel, x: float, y: float, ground_m: float) -> mujoco.MjData:
    data = mujoco.MjData(atlas.model)
    adr = atlas.free_qpos_adr
    data.qpos[adr:adr + 3] = (x, y, ground_m + TABLE.SPAWN_HEIGHT_M - 5e-4)
    mujoco.mj_forward(atlas.model, data)
    return data


def test_feet_friction_combines_as_ode_did(atlas: model.AtlasModel) -> None:
    spin_roll = TABLE.FOOT_FRICTION[1:]
    on_terrain = stand_at(atlas, -3.0, -36.0, 0.03)
    assert contact_frictions(atlas.model, on_terrain, 'l_foot_sole') == {
        ('terrain', (1.0, 1.0, *spin_roll, spin_roll[1]), 6)}
    in_pit = stand_at(atlas, *vertex_xy(*PIT_FLOOR), course.MUD_FLOOR_Z_M)
    assert contact_frictions(atlas.model, in_pit, 'r_foot_sole') == {
        ('mud_ground_plane', (0.5, 0.5, *spin_roll, spin_roll[1]), 6)}
    # The pen floor lies 5 mm under the terrain's 0.03 m: its figure, as the rule gives it.
    m = atlas.model
    pen, sole = m.geom('pen_floor'), m.geom('l_foot_sole')
    assert pen.priority[0] > sole.priority[0]
    assert pen.friction[0] == pytest.approx(min(course.FOOT_FRICTION,
                                                course.PEN_FLOOR_FRICTION))
    block = m.geom('cinder_block_0_0')
    assert block.priority[0] > sole.priority[0]
    assert block.friction[0] == pytest.approx(1.0)
    assert int(block.condim[0]) == 6


def test_vrc_robot_is_atlas_v1_with_hands_and_hokuyo(atlas: model.AtlasModel) -> None:
    m, v1 = atlas.model, model.load_model().model
    def hinges(of: mujoco.MjModel) -> list[str]:
        return [of.joint(j).name for j in range(of.njnt)
                if of.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    assert hinges(m) == hinges(v1)
    assert sorted(hinges(m)) == sorted(JOINT_NAMES)
    assert [m.actuator(a).name for a in range(m.nu)] == list(JOINT_NAMES)
    assert [m.sensor(s).name for s in range(m.nsensor)] == \
        [v1.sensor(s).name for s in range(v1.nsensor)]
    robot = m.body_subtreemass[atlas.pelvis_body_id]
    hand = 1.303 + 4 * (0.25 + 0.106 + 2 * 0.033 + 3 * 0.01)
    assert robot == pytest.approx(v1.body_subtreemass[0] + 2 * hand + 0.057654, abs=1e-6)
    for side in 'lr':
        palm = m.body(f'{side}_palm')
        assert m.body(int(palm.parentid[0])).name == f'{side}_hand'
        assert np.linalg.norm(palm.pos) == pytest.approx(0.1)
        assert m.body_subtreemass[palm.id] == pytest.approx(hand)
    assert m.body(int(m.body('hokuyo_link').parentid[0])).name == 'head'


@pytest.mark.parametrize('start', sorted(course.STARTS))
def test_spawn_stands_on_the_ground_at_each_start(atlas: model.AtlasModel, start: str) -> None:
    m = atlas.model
    data = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, data, m.key(start).id)
    mujoco.mj_forward(m, data)
    figures = course.STARTS[start]
    adr = atlas.free_qpos_adr
    np.testing.assert_allclose(data.qpos[adr:adr + 2], (figures.x_m, figures.y_m))
    assert 2 * math.atan2(data.qpos[adr + 6], data.qpos[adr + 3]) == \
        pytest.approx(figures.yaw_rad)
    ground = Ground(m, data)
    clearances = []
    for sole in ('l_foot_sole', 'r_foot_sole'):
        box = data.geom(sole)
        rotation, half = box.xmat.reshape(3, 3), m.geom(sole).size
        for sx in (-1, 1):
            for sy in (-1, 1):
                x, y, z = box.xpos + rotation @ (half * (sx, sy, -1))
                clearances.append(z - ground.height_m(x, y))
    # The lowest corner on the ground, none in it.
    assert min(clearances) == pytest.approx(0.0, abs=1e-6)
    if start == course.WORLD_NAME:  # the file's own spawn: the free joint's qpos0
        np.testing.assert_allclose(m.qpos0[adr:adr + 7], data.qpos[adr:adr + 7])
