"""The sole module: the model's sole box, and its corners where the model puts them."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.balance import (
    SOLE_GEOMS,
    SoleBox,
    box_corners,
    place_in_stand_pose,
    sole_corners,
)
from tutorial_atlas_control.balance.sole import lowest_sole_corner_m, sole_geom_ids
from tutorial_atlas_control.sim import AtlasModel, load_model


@pytest.fixture(scope='module')
def atlas() -> AtlasModel:
    return load_model()


def test_the_sole_box_is_the_models(atlas: AtlasModel) -> None:
    sole = SoleBox.of(atlas.model)
    for geom in sole_geom_ids(atlas.model):  # the two soles are the same box
        np.testing.assert_allclose(atlas.model.geom_size[geom],
                                   [sole.half_length_m, sole.half_width_m,
                                    sole.half_thickness_m])
        assert abs(float(atlas.model.geom_pos[geom][0])) == pytest.approx(sole.ahead_m)
    # About the 26 x 12.5 cm sole 4.8 cm ahead of the ankle the footprints plot drew.
    assert (2 * sole.half_length_m, 2 * sole.half_width_m) == pytest.approx((0.26, 0.125),
                                                                            abs=1e-3)
    assert sole.ahead_m == pytest.approx(0.048, abs=1e-3)


def test_the_corners_are_the_bottom_face_counter_clockwise_from_front_left(
        atlas: AtlasModel) -> None:
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    assert lowest_sole_corner_m(atlas.model, data) == pytest.approx(0.0, abs=1e-9)
    sole = SoleBox.of(atlas.model)
    for name in SOLE_GEOMS:
        corners = sole_corners(atlas.model, data, name)
        geom = atlas.model.geom(name).id
        rotation = data.geom_xmat[geom].reshape(3, 3)
        local = (corners - data.geom_xpos[geom]) @ rotation
        np.testing.assert_allclose(local, [[1, 1, -1], [1, -1, -1], [-1, -1, -1], [-1, 1, -1]]
                                   * atlas.model.geom_size[geom], atol=1e-12)
        # The bottom face's corners from its centre, with no thickness, are the same points.
        bottom_centre = data.geom_xpos[geom] - sole.half_thickness_m * rotation[:, 2]
        np.testing.assert_allclose(
            box_corners(bottom_centre, rotation, (*sole.half_size_m, 0.0)), corners,
            atol=1e-12)
