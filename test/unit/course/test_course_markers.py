"""course/markers.py: the course's static shapes as rviz draws them. The terrain's mesh runs
through the ground the robot stands on (sim/ground.py's heights) within the triangle budget;
each gate's boxes stand where course.GATES puts the gate; the mud is its own translucent
colour; a bad area is refused with its reason."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from support.vrc_world import WORLD_PATH
from tutorial_atlas_control.course import (
    COURSE_AREA,
    GATES,
    MAX_TRIANGLES,
    MUD_BOX,
    Area,
    BoxShape,
    CourseError,
    CourseShapes,
    Gate,
    course_shapes,
)
from tutorial_atlas_control.course.vrc_task_2 import GATE_POST_M, GATE_WIDTH_M
from tutorial_atlas_control.sim.ground import Ground

#: The mesh's vertices are the heightfield's own: the ground under them within 1 cm.
HEIGHT_TOLERANCE_M = 0.01
#: Vertices checked against the ground (a seeded sample of the mesh's ~30k corners).
SAMPLED_VERTICES = 3000
#: A gate's post is 2.5 m from its centre along the gate's width; the bar at z 4.1.
POST_OFFSET_M = 2.5
BAR_Z_M = 4.1


@pytest.fixture(scope='module')
def world() -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_path(str(WORLD_PATH))


@pytest.fixture(scope='module')
def shapes(world: mujoco.MjModel) -> CourseShapes:
    return course_shapes(world)


def test_the_terrain_mesh_lies_on_the_ground_under_it(world: mujoco.MjModel,
                                                      shapes: CourseShapes) -> None:
    (mesh,) = shapes.terrains
    corners = mesh.triangles.reshape(-1, 3)
    picked = corners[np.random.default_rng(7).choice(len(corners), SAMPLED_VERTICES,
                                                     replace=False)]
    data = mujoco.MjData(world)
    mujoco.mj_forward(world, data)
    ground = Ground(world, data)
    terrain = mujoco.mj_name2id(world, mujoco.mjtObj.mjOBJ_GEOM, 'terrain')
    hits = [ground.hit(x, y) for x, y, _z in picked]
    on_terrain = np.array([hit.geom_id == terrain for hit in hits])
    heights = np.array([hit.height_m for hit in hits])
    error = np.abs(heights - picked[:, 2])
    print(f'{on_terrain.sum()} of {len(picked)} sampled vertices on the terrain, '
          f'worst |z - ground| {error[on_terrain].max():.2e} m')
    assert error[on_terrain].max() <= HEIGHT_TOLERANCE_M
    # Elsewhere something stands on the terrain (a wall, a post, the pit's floor plane).
    assert np.all(heights[~on_terrain] >= picked[~on_terrain, 2] - HEIGHT_TOLERANCE_M)
    assert on_terrain.mean() > 0.9


def test_the_mesh_covers_the_course_within_the_triangle_budget(shapes: CourseShapes) -> None:
    (mesh,) = shapes.terrains
    assert len(mesh.triangles) <= MAX_TRIANGLES
    x, y = mesh.triangles[..., 0], mesh.triangles[..., 1]
    assert COURSE_AREA.x_min <= x.min() < COURSE_AREA.x_min + mesh.cell_m
    assert COURSE_AREA.x_max - mesh.cell_m < x.max() <= COURSE_AREA.x_max
    assert COURSE_AREA.y_min <= y.min() < COURSE_AREA.y_min + mesh.cell_m
    assert COURSE_AREA.y_max - mesh.cell_m < y.max() <= COURSE_AREA.y_max
    # Every triangle faces up (counter-clockwise from above): rviz lights its top side.
    edges = np.cross(mesh.triangles[:, 1] - mesh.triangles[:, 0],
                     mesh.triangles[:, 2] - mesh.triangles[:, 0])
    assert np.all(edges[:, 2] > 0)
    # Coloured by height: the pit's floor darker than the high hilltops.
    low, high = np.argmin(mesh.triangles[..., 2]), np.argmax(mesh.triangles[..., 2])
    colours = mesh.colours.reshape(-1, 4)
    assert colours[low, :3].sum() < colours[high, :3].sum()


def test_a_smaller_budget_takes_a_larger_stride(world: mujoco.MjModel,
                                                shapes: CourseShapes) -> None:
    (full,) = shapes.terrains
    (small,) = course_shapes(world, max_triangles=2000).terrains
    assert len(small.triangles) <= 2000 < len(full.triangles)
    assert small.stride > full.stride


def box_corners(box: BoxShape) -> np.ndarray:
    """The box's eight corners in the world."""
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, box.quat)
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    return box.centre + (signs * box.size / 2) @ rotation.reshape(3, 3).T


@pytest.mark.parametrize('gate', GATES, ids=[gate.name for gate in GATES])
def test_each_gate_stands_where_the_course_puts_it(gate: Gate, shapes: CourseShapes) -> None:
    boxes = {box.name: box for box in shapes.boxes}
    across = np.array([-math.sin(gate.yaw_rad), math.cos(gate.yaw_rad)])  # the gate's +y
    centre = np.array([gate.x_m, gate.y_m])
    for side, sign in (('left', 1), ('right', -1)):
        post = box_corners(boxes[f'{gate.name}_{side}'])
        assert np.allclose(post[:, :2].mean(axis=0), centre + sign * POST_OFFSET_M * across,
                           atol=1e-3)
        assert post[:, 2].min() == pytest.approx(0.0, abs=1e-9)
        assert post[:, 2].max() == pytest.approx(GATE_POST_M[2], abs=1e-9)
    bar = box_corners(boxes[f'{gate.name}_top'])
    assert np.allclose(bar.mean(axis=0), [gate.x_m, gate.y_m, BAR_Z_M], atol=1e-3)
    span = (bar[:, :2] - centre) @ across
    assert span.max() - span.min() == pytest.approx(GATE_WIDTH_M, abs=1e-3)


def test_the_mud_is_its_own_translucent_box(shapes: CourseShapes) -> None:
    boxes = {box.name: box for box in shapes.boxes}
    mud = boxes['mud_atlas']
    assert np.allclose(mud.centre, MUD_BOX.centre_m) and np.allclose(mud.size, MUD_BOX.size_m)
    assert 0 < mud.rgba[3] < 1
    assert not any(np.allclose(mud.rgba, box.rgba) for box in shapes.boxes if box is not mud)
    # Static shapes only: the loose cinder blocks and the robot are not among them.
    assert not any(name.startswith(('cinder_block', 'pelvis')) for name in boxes)
    assert {name.split('_')[0] for name in boxes} == {'mud', 'pen', 'gate'}
    # The pen's floor, 5 mm under the terrain, would only flicker through it.
    assert 'pen_floor' not in boxes and 'pen_wall_0' in boxes


def test_an_area_off_the_terrain_is_refused_with_its_reason(world: mujoco.MjModel) -> None:
    with pytest.raises(CourseError, match=r'terrain terrain: fewer than 2 x 2 of its '
                                          r'vertices lie in x 60.0..70.0, y 0.0..1.0 m'):
        course_shapes(world, area=Area(60.0, 70.0, 0.0, 1.0))
