"""sensors/heightfield_march.py: the march that skips what the tiles rule out gives a full
march's distances bit for bit, over a field of sharp spikes and from every side of it."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.sensors import (
    MARCH_STEP_M,
    Heightfield,
)

#: Random origins and ray bundles compared.
CASES = 60
RAYS = 240
RANGE_M = 30.0


def full_march(field: Heightfield, origin: np.ndarray, rays: np.ndarray,
               range_m: float) -> np.ndarray:
    """The reference: every step of every ray evaluated (the laser's first version; the
    bisection after it is the module's)."""
    result = np.full(len(rays), -1.0)
    if field.height_m(origin[:1], origin[1:2])[0] >= origin[2]:
        return np.zeros(len(rays))
    reach = np.full(len(rays), float(range_m))
    falling = rays[:, 2] < 0.0
    reach[falling] = np.minimum(reach[falling], (origin[2] - field.lowest) / -rays[falling, 2])
    if origin[2] > field.highest:
        reach[~falling] = 0.0
    live = np.flatnonzero(reach > 0.0)
    if not len(live):
        return result
    steps = np.arange(MARCH_STEP_M, float(reach[live].max()) + MARCH_STEP_M, MARCH_STEP_M)
    points = origin + steps[:, None, None] * rays[live]
    below = ((points[..., 2] <= field.height_m(points[..., 0], points[..., 1]))
             & (steps[:, None] <= reach[live] + MARCH_STEP_M))
    met = below.any(axis=0)
    first = np.argmax(below, axis=0)[met]
    near = np.where(first > 0, steps[np.maximum(first - 1, 0)], 0.0)
    distance = field.crossing_m(origin, rays[live[met]], near, steps[first])
    within = distance <= range_m
    result[live[met][within]] = distance[within]
    return result


def spiky_model() -> mujoco.MjModel:
    """A 20 m field of 0.2 m cells, gentle waves with single-vertex spikes 2 m high: a
    spike a tile away from a segment's start is what an undilated tile test would miss."""
    rng = np.random.default_rng(4)
    xs = np.linspace(0.0, 1.0, 101)
    heights = 0.2 + 0.1 * np.sin(9.0 * xs)[None, :] * np.cos(7.0 * xs)[:, None]
    heights[rng.integers(0, 101, 60), rng.integers(0, 101, 60)] = 1.0
    elevation = ' '.join(f'{z:.6f}' for z in heights.ravel())
    return mujoco.MjModel.from_xml_string(f'''<mujoco><asset>
      <hfield name="spikes" nrow="101" ncol="101" size="10 10 2 0.1" elevation="{elevation}"/>
      </asset><worldbody><geom type="hfield" hfield="spikes" pos="1 -1 -0.3"/></worldbody>
      </mujoco>''')


@pytest.fixture(scope='module')
def spiky() -> Heightfield:
    """spiky_model's field, marched as the laser marches it (compiled when built)."""
    return Heightfield(spiky_model(), 0)


def test_skipping_the_tiles_keeps_a_full_marchs_distances(spiky: Heightfield) -> None:
    rng = np.random.default_rng(11)
    hits = 0
    for _ in range(CASES):
        origin = np.array([rng.uniform(-14, 16), rng.uniform(-16, 14), rng.uniform(-0.2, 2.5)])
        rays = rng.normal(size=(RAYS, 3)) * (1.0, 1.0, 0.3)
        rays /= np.linalg.norm(rays, axis=1, keepdims=True)
        ours, theirs = (march(origin, rays, RANGE_M) for march in (
            spiky.distances, lambda o, r, m: full_march(spiky, o, r, m)))
        np.testing.assert_array_equal(ours, theirs)
        hits += int((theirs > 0.0).sum())
    assert hits > 0.1 * CASES * RAYS  # the comparison is of hits, not of misses alone


def test_a_segment_is_shorter_than_a_tile(spiky: Heightfield) -> None:
    assert spiky.segment_steps * MARCH_STEP_M <= 8 * 0.2 + 1e-12
    assert spiky.segment_steps == 8


def test_compiled_march_is_numpys_bit_for_bit(spiky: Heightfield) -> None:
    """The library's march (src/atlas_heightfield.c) against this module's numpy, on the
    spikes from above, from under the surface, and with rays going up over the top."""
    numpy_field = Heightfield(spiky_model(), 0, compiled=False)
    assert spiky.compiled and not numpy_field.compiled
    rng = np.random.default_rng(12)
    hits = 0
    for case in range(CASES):
        z = (-0.5, 3.5, rng.uniform(-0.2, 2.5))[case % 3]  # under, over the top, between
        origin = np.array([rng.uniform(-14, 16), rng.uniform(-16, 14), z])
        rays = rng.normal(size=(RAYS, 3)) * (1.0, 1.0, 0.3)
        rays /= np.linalg.norm(rays, axis=1, keepdims=True)
        ours = spiky.distances(origin, rays, RANGE_M)
        np.testing.assert_array_equal(ours, numpy_field.distances(origin, rays, RANGE_M))
        hits += int((ours > 0.0).sum())
    assert hits > 0.1 * CASES * RAYS
