"""The laser's height map on synthetic scans: a spinning Hokuyo (sensors/laser.py, with its
noise) 1.6 m over a flat floor with a cinder block on it, and over a ramp; the map's heights
against the ground's true ones, the block an obstacle, the robot's own cylinder left out."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.sensors import HokuyoLaser
from tutorial_atlas_control.sensors.height_map import HeightMap, HeightMapSpec, scan_points

#: A head 1.6 m over a floor, a block 0.4 x 0.4 x 0.2 m 2 m ahead and 0.8 m to the left.
FLOOR_WORLD = """
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="0 0 1"/>
    <geom name="block" type="box" size="0.2 0.2 0.1" pos="2 0.8 0.1"/>
    <body name="head" pos="0 0 1.6"><geom type="sphere" size="0.1"/></body>
  </worldbody>
</mujoco>
"""
#: The same head over a ramp rising 10 degrees along +x (a slab turned about y).
RAMP_WORLD = """
<mujoco>
  <worldbody>
    <geom name="ramp" type="box" size="20 20 0.1" euler="0 -10 0"/>
    <body name="head" pos="0 0 1.6"><geom type="sphere" size="0.1"/></body>
  </worldbody>
</mujoco>
"""
SPINDLE_RAD_S = 1.0


def _spun_map(world: str, spec: HeightMapSpec | None = None
              ) -> tuple[HeightMap, mujoco.MjModel, mujoco.MjData]:
    """The map of half a turn of the spindle (40 scans a second) over `world`."""
    model = mujoco.MjModel.from_xml_string(world)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    laser = HokuyoLaser(model, seed=3)
    height_map = HeightMap(spec)
    ranges = np.zeros(laser.spec.samples, dtype=np.float32)
    for k in range(round(math.pi / SPINDLE_RAD_S * laser.spec.rate_hz)):
        angle = k * SPINDLE_RAD_S / laser.spec.rate_hz
        laser.scan(data, angle, k, ranges)
        origin, rotation = laser.frame_pose(data, angle)
        height_map.add_scan(origin, rotation, laser.spec.angles(), ranges, (0.0, 0.0))
    return height_map, model, data


def _true_height(model: mujoco.MjModel, data: mujoco.MjData, x: float, y: float) -> float:
    """The world's top under (x, y): a ray straight down, the head left out."""
    geom = np.zeros(1, dtype=np.int32)
    head = int(model.body('head').id)
    distance = mujoco.mj_ray(model, data, np.array([x, y, 5.0]), np.array([0.0, 0.0, -1.0]),
                             None, 1, head, geom)
    return 5.0 - distance


def _ring(inner_m: float, outer_m: float, count: int = 400) -> np.ndarray:
    """Points (x, y) spread over a ring around the head, seeded."""
    rng = np.random.default_rng(5)
    radius = np.sqrt(rng.uniform(inner_m ** 2, outer_m ** 2, count))
    bearing = rng.uniform(-math.pi, math.pi, count)
    return np.stack((radius * np.cos(bearing), radius * np.sin(bearing)), 1)


def test_height_map_of_a_flat_floor_is_within_a_centimetre_and_covers_the_near_ground(
) -> None:
    height_map, model, data = _spun_map(FLOOR_WORLD)
    heights = np.array([height_map.height_m(x, y) for x, y in _ring(0.8, 4.0)])
    known = np.isfinite(heights)
    assert known.mean() > 0.4, 'half a turn of the spindle sees much of the near ground'
    assert np.abs(heights[known]).max() < 0.01
    assert np.median(np.abs(heights[known])) < 0.004


def test_height_map_leaves_out_the_robots_own_cylinder() -> None:
    height_map, _, _ = _spun_map(FLOOR_WORLD)
    points = height_map.points
    assert np.hypot(points[:, 0], points[:, 1]).min() > HeightMapSpec().self_radius_m
    assert math.isnan(height_map.height_m(0.05, 0.0))
    height, distance = height_map.nearest_m(0.05, 0.0)
    assert abs(height) < 0.015 and 0.1 < distance < 0.5, 'the nearest seen floor'


def test_height_map_takes_a_block_for_an_obstacle_not_for_ground() -> None:
    height_map, _, _ = _spun_map(FLOOR_WORLD)
    grid = height_map.grid
    row, col = (int(round(v)) for v in grid.index(2.0, 0.8))
    assert grid.hits[row, col] > 0, 'the laser saw the block'
    assert grid.obstacle[row - 1:row + 2, col - 1:col + 2].all()
    assert math.isnan(height_map.height_m(2.0, 0.8))
    beside = [height_map.height_m(2.0, y) for y in np.arange(0.1, 0.45, 0.05)]
    assert any(math.isfinite(h) for h in beside)
    assert all(abs(h) < 0.02 for h in beside if math.isfinite(h)), 'the floor beside it'


def test_height_map_follows_a_ramp() -> None:
    height_map, model, data = _spun_map(RAMP_WORLD)
    errors = []
    for x, y in _ring(0.8, 4.0):
        height = height_map.height_m(x, y)
        if math.isfinite(height):
            errors.append(height - _true_height(model, data, x, y))
    assert len(errors) > 150
    assert np.abs(errors).max() < 0.015
    assert abs(float(np.median(errors))) < 0.003, 'no offset along the slope'


def test_scan_points_places_rays_in_the_frame() -> None:
    quarter = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # yaw 90 deg
    points = scan_points(np.array([1.0, 2.0, 3.0]), quarter, np.array([0.0, math.pi / 2, 1.0]),
                         np.array([2.0, 1.0, np.inf]))
    np.testing.assert_allclose(points, [[1.0, 4.0, 3.0], [0.0, 2.0, 3.0]], atol=1e-12)


def test_height_map_spec_refuses_nonsense() -> None:
    with pytest.raises(ValueError, match='height map'):
        HeightMapSpec(cell_m=0.0)
    with pytest.raises(ValueError, match='height map'):
        HeightMapSpec(percentile=120.0)

