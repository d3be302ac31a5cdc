"""sim/fall.py: the fall criterion and its two stricter siblings, on the plane at z 0 and on
a raised block, measured from the ground under the lower sole."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.sim import (
    FALL_HEIGHT_M,
    FALLING_PELVIS_M,
    FALLING_TILT_RAD,
    MODEL_PATH,
    SPAWN_HEIGHT_M,
    STANDING_PELVIS_M,
    AtlasModel,
    GroundUnderFeet,
    fallen,
    fallen_samples,
    falling,
    load_model,
    standing,
)

BLOCK_M = 0.3


def test_the_flat_ground_form_is_the_old_absolute_threshold() -> None:
    assert (FALL_HEIGHT_M, FALLING_PELVIS_M, FALLING_TILT_RAD, STANDING_PELVIS_M) == (
        0.5, 0.7, 0.5, 0.8)
    heights = np.array([0.93, 0.5, np.nextafter(0.5, 0.0), 0.2])
    np.testing.assert_array_equal(fallen_samples(heights), heights < 0.5)
    assert [fallen(float(z)) for z in heights] == [False, False, True, True]
    assert standing(0.8) and not standing(0.799) and standing(0.85)
    assert falling(0.69, 1.0) and not falling(0.71, 1.0)
    assert falling(0.9, math.cos(0.51)) and not falling(0.9, math.cos(0.49))


def test_the_predicates_measure_from_the_ground_given() -> None:
    assert not fallen(0.9, BLOCK_M) and fallen(0.75, BLOCK_M)
    assert not falling(1.05, 1.0, BLOCK_M) and falling(0.95, 1.0, BLOCK_M)
    assert standing(1.15, BLOCK_M) and not standing(1.05, BLOCK_M)
    np.testing.assert_array_equal(fallen_samples(np.array([0.9, 0.75]), BLOCK_M), [False, True])


def placed(atlas: AtlasModel, pelvis_z_m: float, x_m: float = 0.0) -> mujoco.MjData:
    """The robot upright, every joint at 0, its pelvis at (x_m, 0, pelvis_z_m)."""
    data = mujoco.MjData(atlas.model)
    adr = atlas.free_qpos_adr
    data.qpos[adr:adr + 7] = (x_m, 0.0, pelvis_z_m, 1.0, 0.0, 0.0, 0.0)
    mujoco.mj_forward(atlas.model, data)
    return data


def test_on_the_plane_the_ground_is_z_0_without_rays() -> None:
    atlas = load_model()
    data = placed(atlas, SPAWN_HEIGHT_M)
    feet = GroundUnderFeet(atlas, data)
    assert feet.ground.level_m == 0.0 and feet.height_m() == 0.0
    assert feet.clearance_m() == SPAWN_HEIGHT_M
    assert not feet.fallen() and not feet.falling() and feet.standing()
    data.qpos[atlas.free_qpos_adr + 2] = 0.45
    assert feet.fallen() and feet.fallen(0.45) and not feet.fallen(0.55)


@pytest.fixture(scope='module')
def on_a_block(tmp_path_factory: pytest.TempPathFactory) -> AtlasModel:
    """The Atlas model with a 2 m x 2 m block, BLOCK_M high, around x = 0 on the floor."""
    text = MODEL_PATH.read_text()
    floor = text.index('<geom name="floor"')
    block = (f'<geom name="block" type="box" size="1 1 {BLOCK_M / 2}" '
             f'pos="0 0 {BLOCK_M / 2}"/>\n    ')
    path = Path(tmp_path_factory.mktemp('block')) / 'atlas_on_a_block.xml'
    path.write_text(text[:floor] + block + text[floor:])
    return load_model(path)


def test_standing_on_a_block_is_measured_from_the_block(on_a_block: AtlasModel) -> None:
    data = placed(on_a_block, BLOCK_M + SPAWN_HEIGHT_M)  # soles on the block's top
    feet = GroundUnderFeet(on_a_block, data)
    assert feet.ground.level_m is None
    assert feet.height_m() == pytest.approx(BLOCK_M, abs=1e-9)
    assert not feet.fallen() and not feet.falling() and feet.standing()
    # the pelvis 0.6 m above the block's top is not fallen; 0.6 m above the floor, on the
    # block, it is (0.3 m above where the robot stands), though the old absolute 0.5 m
    # threshold called it up
    assert not feet.fallen(BLOCK_M + 0.6)
    assert feet.fallen(0.6)
    assert feet.falling() is falling(float(data.xpos[on_a_block.pelvis_body_id][2]), 1.0,
                                     BLOCK_M)


def test_beside_the_block_the_floor_counts(on_a_block: AtlasModel) -> None:
    data = placed(on_a_block, SPAWN_HEIGHT_M, x_m=2.0)
    feet = GroundUnderFeet(on_a_block, data)
    assert feet.height_m() == pytest.approx(0.0, abs=1e-9)
    assert not feet.fallen(0.6) and feet.fallen(0.45)


def test_the_lower_sole_says_where_the_robot_stands(on_a_block: AtlasModel) -> None:
    """One sole on the block, the other on the floor beside it (placed by hand, as the last
    mj_forward would have): the ground is the floor's, under the lower sole."""
    data = placed(on_a_block, 1.2)
    feet = GroundUnderFeet(on_a_block, data)
    left, right = (on_a_block.model.geom(name).id for name in ('l_foot_sole', 'r_foot_sole'))
    data.geom_xpos[left] = (0.5, 0.2, BLOCK_M + 0.005)
    data.geom_xpos[right] = (1.3, -0.2, 0.005)
    assert feet.height_m() == pytest.approx(0.0, abs=1e-9)
    data.geom_xpos[right] = (1.3, -0.2, BLOCK_M + 0.1)  # lifted above the block: swinging
    assert feet.height_m() == pytest.approx(BLOCK_M, abs=1e-9)


def test_no_ray_while_the_pelvis_is_high_above_all_ground(on_a_block: AtlasModel) -> None:
    feet = GroundUnderFeet(on_a_block, placed(on_a_block, BLOCK_M + SPAWN_HEIGHT_M))
    assert feet.ground.top_m() == pytest.approx(BLOCK_M, abs=1e-9)
    calls = []
    feet.height_m = lambda: calls.append(1) or BLOCK_M  # type: ignore[method-assign]
    assert not feet.fallen(feet.ground.top_m() + FALL_HEIGHT_M + 0.01)
    assert calls == []
    assert feet.fallen(BLOCK_M + 0.4) and calls == [1]
