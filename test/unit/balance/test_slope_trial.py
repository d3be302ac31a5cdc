"""The slope trials' world and start (balance/slope_trial.py): the floor tilted as asked, and
the robot placed upright on it with both soles lying on the incline."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.balance.slope_trial import place_on_slope, slope_model
from tutorial_atlas_control.balance.sole import sole_corners
from tutorial_atlas_control.sim import SOLE_GEOMS, Ground


@pytest.mark.parametrize('slope_deg', [0.0, 8.0, 16.0])
def test_the_robot_stands_upright_with_its_soles_on_the_incline(slope_deg: float) -> None:
    slope = math.radians(slope_deg)
    atlas = slope_model(slope)
    ground = Ground(atlas.model)
    normal = np.array([-math.sin(slope), 0.0, math.cos(slope)])
    np.testing.assert_allclose(ground.normal(0.3, -0.2), normal, atol=1e-9)
    assert ground.height_m(0.5, 0.0) == pytest.approx(0.5 * math.tan(slope), abs=1e-9)
    data = mujoco.MjData(atlas.model)
    place_on_slope(atlas, data, slope, ground)
    corners = np.concatenate([sole_corners(atlas.model, data, name) for name in SOLE_GEOMS])
    heights, _ = ground.hits(corners[:, :2])
    above = corners[:, 2] - heights
    assert float(np.min(above)) == pytest.approx(0.0, abs=1e-9)
    # Every corner on the incline, as DRCSim's Stand pose puts them on flat ground (its soles
    # pitched 11 mrad: a corner 2.8 mm up).
    assert float(np.max(above)) < 3e-3
    for name in SOLE_GEOMS:
        sole_up = data.geom_xmat[atlas.model.geom(name).id].reshape(3, 3)[:, 2]
        assert float(sole_up @ normal) > math.cos(0.02)
    pelvis_up = data.xmat[atlas.pelvis_body_id].reshape(3, 3)[:, 2]
    assert float(pelvis_up[2]) == pytest.approx(1.0, abs=1e-9)
