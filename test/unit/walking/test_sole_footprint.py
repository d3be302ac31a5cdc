"""The plane a sole rests on over a heightfield (walking/sole_footprint.py)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.sim import Ground
from tutorial_atlas_control.walking import SOLE_HALF_LENGTH_M, SOLE_HALF_WIDTH_M
from tutorial_atlas_control.walking.sole_footprint import footprint_surface

#: Atlas's sole's bottom face, half length and half width (m).
HALF_SIZE_M = (SOLE_HALF_LENGTH_M, SOLE_HALF_WIDTH_M)
#: A 9 x 9 heightfield over 2 x 2 m (0.25 m cells), 0.4 m of relief; a box from its edge on.
ROWS = 9


def _world(elevation: np.ndarray) -> Ground:
    values = ' '.join(f'{v:.6f}' for v in elevation.ravel())
    xml = f'''<mujoco><asset>
      <hfield name="hills" nrow="{ROWS}" ncol="{ROWS}" size="1 1 0.4 0.1" elevation="{values}"/>
    </asset><worldbody>
      <geom name="hills" type="hfield" hfield="hills"/>
      <geom name="block" type="box" pos="1.3 0 0.1" size="0.3 0.3 0.1"/>
    </worldbody></mujoco>'''
    model = mujoco.MjModel.from_xml_string(xml)
    return Ground(model)


def _surface(ground: Ground, x_m: float, y_m: float, yaw_rad: float
             ) -> tuple[float, tuple[float, float, float]] | None:
    """footprint_surface as on_ground calls it: the centre's height from its own hit."""
    return footprint_surface(ground, x_m, y_m, yaw_rad, HALF_SIZE_M, ground.height_m(x_m, y_m))


def _ramp() -> np.ndarray:
    """Heights rising along x (columns), 0 to 1 of the relief: a 0.4 m rise over 2 m."""
    return np.tile(np.linspace(0.0, 1.0, ROWS), (ROWS, 1))


def test_on_an_even_slope_the_plane_is_the_slope() -> None:
    ground = _world(_ramp())
    assert ground.hfield_geoms == frozenset({0})
    height, normal = _surface(ground, 0.1, 0.05, 0.3)
    slope = 0.4 / 2.0
    assert normal == pytest.approx((-slope / math.hypot(slope, 1.0), 0.0,
                                    1.0 / math.hypot(slope, 1.0)), abs=1e-9)
    assert height == pytest.approx(ground.height_m(0.1, 0.05), abs=1e-9)


def test_a_bump_under_a_corner_raises_the_plane_to_it() -> None:
    elevation = _ramp()
    elevation[4, 5] += 0.05  # the vertex at (0.25, 0) about 2 cm up
    ground = _world(elevation)
    x, y = 0.13, 0.0  # the sole's front corners at x 0.26, beside that vertex
    height, normal = _surface(ground, x, y, 0.0)
    corners = [(x + a * HALF_SIZE_M[0], y + b * HALF_SIZE_M[1])
               for a in (1.0, -1.0) for b in (1.0, -1.0)] + [(x, y)]
    for cx, cy in corners:  # no sampled point above the plane, one on it
        plane = height - ((cx - x) * normal[0] + (cy - y) * normal[1]) / normal[2]
        assert ground.height_m(cx, cy) <= plane + 1e-9
    assert min(height - ((cx - x) * normal[0] + (cy - y) * normal[1]) / normal[2]
               - ground.height_m(cx, cy) for cx, cy in corners) == pytest.approx(0.0, abs=1e-9)
    ramp = _world(_ramp())
    assert normal[0] < ramp.normal(x, y)[0] - 0.01  # steeper: the front is raised


def test_a_sole_partly_off_the_heightfield_has_none() -> None:
    ground = _world(_ramp())
    # Centred on the heightfield beside its edge (x 1), its front corners on the box.
    assert ground.hit(0.95 + HALF_SIZE_M[0], 0.0).geom_id == 1
    assert _surface(ground, 0.95, 0.0, 0.0) is None
