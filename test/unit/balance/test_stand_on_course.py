"""Stand on the VRC Task 2 course: its ground is at z 0.03 in the pen, not 0, and the world
holds 150 kg of loose blocks that are not the robot."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from support.vrc_world import WORLD_PATH
from tutorial_atlas_control.balance import StandBehaviour
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.sim import GroundUnderFeet, load_model
from tutorial_atlas_control.sim.controller import DEFAULT_GAINS_FILE, load_gains_yaml
from tutorial_atlas_control.sim.ground import Ground
from tutorial_atlas_control.sim.simulator import AtlasSimulator

STAND_S = 3.0


def test_stand_holds_the_vrc_robot_at_the_pen_start() -> None:
    sim = AtlasSimulator(load_model(WORLD_PATH), load_gains_yaml(DEFAULT_GAINS_FILE),
                         time_to_unpin_s=0.0)
    atlas, data = sim.atlas, sim.data
    adr = atlas.free_qpos_adr
    x, y = atlas.model.qpos0[adr:adr + 2]
    ground_m = Ground(atlas.model).height_m(x, y)
    assert ground_m == pytest.approx(0.03, abs=1e-6)
    place_in_stand_pose(atlas, data, ground_m=ground_m)
    stand = StandBehaviour(atlas)
    sim.install_stand(stand)
    assert stand.estimator.mass_kg == pytest.approx(
        atlas.model.body_subtreemass[atlas.pelvis_body_id])
    under = GroundUnderFeet(atlas, data)
    start = data.qpos[adr:adr + 3].copy()
    lowest = np.inf
    for _ in range(round(STAND_S / sim.dt_s)):
        sim.step()
        lowest = min(lowest, under.clearance_m())
    # Stand's height (0.91 m above the ground, as on the plane), feet and pelvis in place.
    assert lowest > 0.9
    np.testing.assert_allclose(data.qpos[adr:adr + 3], start, atol=0.01)
    mujoco.mj_forward(atlas.model, data)
    assert not under.falling()
