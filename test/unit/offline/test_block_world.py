"""The cinder block trial's world and plans (offline/block_step.py), without stepping: the
block lies loose on the floor with its top at 0.203 m, hollow lying flat (a ray through a
hole under a sole's centre meets the floor, the sole's footprint finds the rims) and solid
on top on its side; the plans' steps."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.offline import PLANS, CinderBlock, block_model, block_plan
from tutorial_atlas_control.sim import Ground
from tutorial_atlas_control.walking import sweep_points, terrain_top_m

SOLE_HALF_SIZE_M = (0.13, 0.0624)


def ground_of(block: CinderBlock) -> Ground:
    atlas = block_model(block)
    data = mujoco.MjData(atlas.model)
    mujoco.mj_forward(atlas.model, data)
    return Ground(atlas.model, data)


def footprint_top(ground: Ground, x: float, y: float) -> float:
    centre = np.array([x, y])
    return terrain_top_m(sweep_points(centre, centre, 0.0, 0.0, SOLE_HALF_SIZE_M),
                         ground.height_m)


def test_lying_flat_a_ray_falls_through_a_hole_and_the_footprint_finds_the_rims() -> None:
    block = CinderBlock()
    ground = ground_of(block)
    assert ground.level_m is None  # a loose block: the ground is cast, not a level
    assert ground.height_m(block.x_m, 0.0) == pytest.approx(block.top_m, abs=2e-3)  # the web
    assert ground.height_m(block.x_m, 0.12) == pytest.approx(0.0, abs=1e-9)  # a hole
    assert footprint_top(ground, block.x_m, 0.12) == pytest.approx(block.top_m, abs=2e-3)
    assert footprint_top(ground, 0.016, 0.12) == pytest.approx(0.0, abs=1e-9)  # the start


def test_on_its_side_its_top_is_one_solid_wall() -> None:
    block = CinderBlock(on_side=True)
    ground = ground_of(block)
    for y in (-0.2, -0.12, 0.0, 0.12, 0.2):
        assert ground.height_m(block.x_m, y) == pytest.approx(block.top_m, abs=2e-3)
    assert ground.height_m(block.x_m + 0.11, 0.0) == pytest.approx(0.0, abs=1e-9)


def test_the_plans_step_onto_the_block_and_off() -> None:
    block = CinderBlock()
    feet = np.array([[0.016, 0.14], [0.016, -0.14]])
    back = block_plan(block, feet, 'back')
    assert [(s.foot_index, s.x_m, s.z_m) for s in back] == [
        (0, block.x_m, block.top_m), (0, 0.016, 0.0)]
    across = block_plan(block, feet, 'across')
    assert [(s.foot_index, s.z_m) for s in across] == [
        (0, block.top_m), (1, block.top_m), (0, 0.0), (1, 0.0)]
    assert across[2].x_m - 0.13 > block.x_m + block.depth_m / 2  # down beyond the far edge
    assert PLANS == ('back', 'across')
    with pytest.raises(ValueError, match="block plan 'up' is not one of"):
        block_plan(block, feet, 'up')
