"""sim/ground.py on small worlds built here, and on the Atlas model: heights and normals."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.sim import Ground, load_model


def world(body: str, assets: str = '') -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_string(
        f'<mujoco><asset>{assets}</asset><worldbody>{body}</worldbody></mujoco>')


@pytest.mark.parametrize('z', [0.0, 0.3])
def test_level_plane(z: float) -> None:
    ground = Ground(world(f'<geom type="plane" size="1 1 0.1" pos="0 0 {z}"/>'))
    for x, y in [(0.0, 0.0), (0.4, -0.7), (25.0, 40.0)]:  # beyond the rendered size too
        hit = ground.hit(x, y)
        assert hit.height_m == pytest.approx(z, abs=1e-9)
        np.testing.assert_allclose(hit.normal, [0.0, 0.0, 1.0], atol=1e-9)
        assert hit.geom_id == 0


def test_tilted_plane() -> None:
    ground = Ground(world('<geom type="plane" size="0 0 1" pos="0.2 -0.1 0.3" '
                          'euler="10 -5 30"/>'))
    rot = np.zeros(9)
    quat = np.zeros(4)
    mujoco.mju_euler2Quat(quat, np.radians([10.0, -5.0, 30.0]), 'xyz')
    mujoco.mju_quat2Mat(rot, quat)
    normal = rot.reshape(3, 3)[:, 2]
    for x, y in [(0.0, 0.0), (3.0, -2.0), (-10.0, 7.0)]:
        # on the plane: normal . (p - origin) = 0
        z = 0.3 - (normal[0] * (x - 0.2) + normal[1] * (y + 0.1)) / normal[2]
        hit = ground.hit(x, y)
        assert hit.height_m == pytest.approx(z, abs=1e-9)
        np.testing.assert_allclose(hit.normal, normal, atol=1e-9)


def test_box_on_plane() -> None:
    ground = Ground(world('<geom type="plane" size="0 0 1"/>'
                          '<geom type="box" size="0.2 0.3 0.15" pos="1 0 0.15"/>'))
    top = ground.hit(1.1, 0.2)
    assert top.height_m == pytest.approx(0.3, abs=1e-9)
    np.testing.assert_allclose(top.normal, [0.0, 0.0, 1.0], atol=1e-9)
    assert top.geom_id == 1
    beside = ground.hit(1.3, 0.0)
    assert beside.height_m == pytest.approx(0.0, abs=1e-9)
    assert beside.geom_id == 0


def test_a_bar_overhead_is_not_the_ground_under_it() -> None:
    """A VRC gate: two posts and a bar 4 m up over ground 3 cm up. Under the bar the ground
    is the ground (a walk through the gate took the bar for it: its steps aimed 4 m up and
    the robot fell); on a post's top and a block resting on the ground, what is on top."""
    ground = Ground(world('<geom type="plane" size="0 0 1" pos="0 0 0.03"/>'
                          '<geom type="box" size="0.1 0.1 2" pos="1 -2.5 2"/>'
                          '<geom type="box" size="0.1 2.6 0.1" pos="1 0 4.1"/>'
                          '<geom type="box" size="0.2 0.1 0.1" pos="3 0 0.13"/>'
                          '<geom type="box" size="0.1 0.1 0.1" pos="3 0 1.2"/>'))
    under = ground.hit(1.05, 0.3)
    assert under.height_m == pytest.approx(0.03, abs=1e-9) and under.geom_id == 0
    assert ground.height_m(1.0, -2.5) == pytest.approx(4.2, abs=1e-9)  # the bar on a post
    assert ground.height_m(3.15, 0.0) == pytest.approx(0.23, abs=1e-9)  # the block's top
    # 0.87 m of free space under a box: within OVERHEAD_CLEARANCE_M, it is ground.
    assert ground.height_m(3.0, 0.0) == pytest.approx(1.3, abs=1e-9)


def test_turned_box_answers_the_face_hit() -> None:
    ground = Ground(world('<geom type="box" size="0.5 0.5 0.5" pos="0 0 0" euler="0 30 0"/>'))
    hit = ground.hit(0.1, 0.0)
    np.testing.assert_allclose(hit.normal, [math.sin(math.radians(30)), 0.0,
                                            math.cos(math.radians(30))], atol=1e-9)


def test_heightfield_heights_at_grid_points() -> None:
    elevation = np.array([[0.0, 1.0, 2.0, 3.0], [4.0, 6.0, 5.0, 7.0], [8.0, 9.0, 11.0, 10.0]])
    size = (1.0, 2.0, 0.5, 0.1)  # radius x, radius y, elevation z, base z
    text = ' '.join(str(v) for v in elevation.ravel())
    model = world('<geom type="hfield" hfield="h" pos="3 1 0.2"/>',
                  f'<hfield name="h" nrow="3" ncol="4" size="{" ".join(map(str, size))}" '
                  f'elevation="{text}"/>')
    ground = Ground(model)
    # MuJoCo scales the elevations to [0, 1], then by size z; the attribute's first row is
    # the +y edge (an image's top row), so row r of the array sits at y from +y down.
    scaled = (elevation - elevation.min()) / np.ptp(elevation) * size[2]
    nrow, ncol = elevation.shape
    for row in range(nrow):
        for col in range(ncol):
            x = 3.0 + (2.0 * col / (ncol - 1) - 1.0) * size[0]
            y = 1.0 + (1.0 - 2.0 * row / (nrow - 1)) * size[1]
            assert ground.height_m(x, y) == pytest.approx(0.2 + scaled[row, col], abs=1e-6)


def test_heightfield_normal_on_a_slope() -> None:
    # rising 1 m per 2 m along x everywhere: the normal is (-0.5, 0, 1), normalised
    model = world('<geom type="hfield" hfield="h"/>',
                  '<hfield name="h" nrow="2" ncol="3" size="2 1 2 0.1" '
                  'elevation="0 1 2 0 1 2"/>')
    hit = Ground(model).hit(0.3, 0.2)
    np.testing.assert_allclose(hit.normal, np.array([-0.5, 0.0, 1.0]) / math.sqrt(1.25),
                               atol=1e-6)
    assert hit.height_m == pytest.approx(1.0 + 0.3 / 2.0, abs=1e-6)


def test_what_cannot_collide_is_not_ground() -> None:
    ground = Ground(world('<geom type="plane" size="0 0 1"/>'
                          '<geom type="box" size="0.2 0.2 0.5" pos="0 0 0.5" contype="0" '
                          'conaffinity="0"/>'
                          '<geom type="box" size="0.2 0.2 0.2" pos="2 0 0.2" rgba="0 0 0 0"/>'))
    assert ground.height_m(0.0, 0.0) == pytest.approx(0.0, abs=1e-9)
    assert ground.height_m(2.0, 0.0) == pytest.approx(0.4, abs=1e-9)  # invisible, solid


def _loose_block(half_size: str, x_m: float) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """A plane and a free 0.2 m high box of half sizes `half_size` resting at x `x_m`."""
    model = world('<geom type="plane" size="0 0 1"/>'
                  '<body name="block" pos="0 0 0.1"><freejoint/>'
                  f'<geom type="box" size="{half_size}" mass="5"/></body>')
    data = mujoco.MjData(model)
    data.qpos[:3] = (x_m, 0.0, 0.1)
    mujoco.mj_forward(model, data)
    return model, data


def test_loose_block_follows_the_data() -> None:
    model, data = _loose_block('0.2 0.1 0.1', 1.0)
    ground = Ground(model, data)
    assert ground.height_m(1.0, 0.0) == pytest.approx(0.2, abs=1e-9)
    assert ground.height_m(0.0, 0.0) == pytest.approx(0.0, abs=1e-9)
    data.qpos[:3] = (0.0, 0.0, 0.1)
    mujoco.mj_forward(model, data)
    assert ground.height_m(0.0, 0.0) == pytest.approx(0.2, abs=1e-9)


def test_nothing_below() -> None:
    hit = Ground(world('<geom type="box" size="0.2 0.2 0.2"/>')).hit(5.0, 5.0)
    assert hit.height_m == -math.inf and hit.geom_id == -1 and np.isnan(hit.normal).all()


def test_batched_matches_single() -> None:
    ground = Ground(world('<geom type="plane" size="0 0 1"/>'
                          '<geom type="box" size="0.2 0.3 0.15" pos="1 0 0.15"/>'))
    xy = np.array([[1.1, 0.2], [1.3, 0.0], [-4.0, 2.0]])
    heights, normals = ground.hits(xy)
    for (x, y), height, normal in zip(xy, heights, normals):
        hit = ground.hit(float(x), float(y))
        assert height == hit.height_m
        np.testing.assert_array_equal(normal, hit.normal)


def test_atlas_world_is_the_floor() -> None:
    atlas = load_model()
    data = mujoco.MjData(atlas.model)
    mujoco.mj_forward(atlas.model, data)
    ground = Ground(atlas.model, data)
    floor = mujoco.mj_name2id(atlas.model, mujoco.mjtObj.mjOBJ_GEOM, 'floor')
    assert ground.geom_ids == (floor,)
    for body in ('l_foot', 'r_foot', 'pelvis'):
        x, y, _ = data.xpos[atlas.model.body(body).id]
        hit = ground.hit(float(x), float(y))
        assert hit.height_m == 0.0 and hit.geom_id == floor
        np.testing.assert_array_equal(hit.normal, [0.0, 0.0, 1.0])


def scattered_blocks(bar: bool, count: int = 20, seed: int = 4
                     ) -> tuple[mujoco.MjModel, mujoco.MjData]:
    """A plane under `count` loose boxes placed and turned at random (the course's kind of
    world: more loose geoms than the Python loop takes), with `bar` a gate bar welded
    overhead."""
    rng = np.random.default_rng(seed)
    bodies = ''.join(f'<body name="b{i}"><freejoint/><geom type="box" size="0.2 0.1 0.1" '
                     'mass="5"/></body>' for i in range(count))
    overhead = '<geom type="box" size="2 0.1 0.1" pos="0 0 4"/>' if bar else ''
    model = world(f'<geom type="plane" size="0 0 1"/>{overhead}{bodies}')
    data = mujoco.MjData(model)
    for i in range(count):
        quat = rng.normal(size=4)
        data.qpos[7 * i:7 * i + 7] = (*rng.uniform(-1.5, 1.5, 2), rng.uniform(0.0, 0.6),
                                      *(quat / np.linalg.norm(quat)))
    mujoco.mj_forward(model, data)
    return model, data


def test_many_loose_blocks_culled_by_numpy_as_by_the_loop(
        monkeypatch: pytest.MonkeyPatch) -> None:
    model, data = scattered_blocks(bar=False)
    ground = Ground(model, data)
    points = np.random.default_rng(5).uniform(-1.8, 1.8, (300, 2)).tolist()
    fast = [ground.hit(x, y) for x, y in points]
    fast_top = ground.top_m()
    monkeypatch.setattr('tutorial_atlas_control.sim.ground._NUMPY_CULL_FROM', 10 ** 6)
    looped = [ground.hit(x, y) for x, y in points]
    assert ground.top_m() == fast_top
    for one, other in zip(fast, looped):
        assert (one.height_m, one.geom_id) == (other.height_m, other.geom_id)
        np.testing.assert_array_equal(one.normal, other.normal)
    assert sum(hit.geom_id > 0 for hit in fast) > 30  # many points on blocks, not the plane
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    highest = max(float(data.geom_xpos[g][2] + (data.geom_xmat[g].reshape(3, 3)
                                                 @ (corners * model.geom_size[g]).T)[2].max())
                  for g in range(1, model.ngeom))
    assert highest <= fast_top <= highest + 0.25  # a bound, within a box's diagonal


def test_clear_above_is_the_bound_on_all_ground() -> None:
    model, data = scattered_blocks(bar=True)
    ground = Ground(model, data)
    top = ground.top_m()
    assert top == pytest.approx(4.1, abs=1e-9)  # the bar
    for z in (top - 0.6, top + 0.49, top + 0.5, top + 0.51, 9.0):
        assert ground.clear_above(z, 0.5) == (z - top >= 0.5)
    data.qpos[2] = 6.0  # a block lifted over the bar: the bound follows it
    mujoco.mj_forward(model, data)
    assert ground.top_m() > 6.0 and not ground.clear_above(4.7, 0.5)


def test_a_block_turned_in_place_is_seen_turned() -> None:
    """The ground keeps its last answer with the question: a block turned about its
    centre (the same position) is a new question, whose answer is the turned block's."""
    model, data = _loose_block('0.2 0.05 0.1', 0.0)
    ground = Ground(model, data)
    assert ground.height_m(0.15, 0.0) == pytest.approx(0.2, abs=1e-9)
    data.qpos[3:7] = (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))  # 90 deg about z
    mujoco.mj_forward(model, data)
    assert ground.height_m(0.15, 0.0) == pytest.approx(0.0, abs=1e-9)
    assert ground.height_m(0.0, 0.15) == pytest.approx(0.2, abs=1e-9)
