"""A finals' variant of the course compiled in memory: the mud floor's friction as the
variant says, each rearranged block where the variant puts it (its body and every start's
keyframe), raised over the ground by the world generator's own rule, and at rest there."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.bags import terrain_heights
from tutorial_atlas_control.course import BLOCKS, course_variant
from tutorial_atlas_control.offline import MUD_FLOOR_GEOM, block_placement, variant_model
from tutorial_atlas_control.resources import package_path


@pytest.fixture(scope='module')
def shipped() -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_path(str(package_path('sim', 'vrc_task_2.xml')))


def test_the_world_s_own_blocks_are_placed_where_the_world_file_has_them(
        shipped: mujoco.MjModel) -> None:
    """block_placement is tools/make_vrc_world.py's rule: the shipped world's 30 blocks."""
    heights = terrain_heights()
    for block in BLOCKS:
        position, quat = block_placement(block, heights)
        body = shipped.body(block.name).id
        assert position == pytest.approx(shipped.body_pos[body], abs=1e-6), block.name
        assert quat == pytest.approx(shipped.body_quat[body], abs=1e-8), block.name


def test_the_mud_floor_variant_changes_only_the_floor_s_friction(
        shipped: mujoco.MjModel) -> None:
    model = variant_model(course_variant('finals_mud_floor')).model
    floor = model.geom(MUD_FLOOR_GEOM).id
    assert model.geom_friction[floor, 0] == 0.3
    assert shipped.geom_friction[floor, 0] == 0.5
    others = np.arange(model.ngeom) != floor
    assert np.array_equal(model.geom_friction[others], shipped.geom_friction[others])
    assert np.array_equal(model.body_pos, shipped.body_pos)


def test_the_rearranged_rubble_starts_where_the_variant_puts_it_and_rests(
        shipped: mujoco.MjModel) -> None:
    variant = course_variant('finals_rubble')
    model = variant_model(variant).model
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key('vrc_task_2_rubble_start').id)
    heights = terrain_heights()
    for block in variant.blocks:
        position, _ = block_placement(block, heights)
        address = model.jnt_qposadr[model.joint(f'{block.name}_free').id]
        assert data.qpos[address:address + 3] == pytest.approx(position, abs=1e-9)
        assert model.body_pos[model.body(block.name).id] == pytest.approx(position, abs=1e-9)
    moved = [b.name for b in variant.blocks
             if np.hypot(*(model.body_pos[model.body(b.name).id][:2]
                           - shipped.body_pos[shipped.body(b.name).id][:2])) > 0.1]
    assert len(moved) >= 25
    # Dropped from 2 mm over the ground, every block settles within a second: none pushed
    # out of the terrain (a block placed into the ground leaves it at metres a second).
    addresses = [model.jnt_dofadr[model.joint(f'{b.name}_free').id] for b in BLOCKS]
    for _ in range(round(1.0 / model.opt.timestep)):
        mujoco.mj_step(model, data)
    speeds = [np.linalg.norm(data.qvel[a:a + 3]) for a in addresses]
    assert max(speeds) < 0.05, max(speeds)
