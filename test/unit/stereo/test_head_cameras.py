"""The rendered pair obeys the camera_info it is published with: a marker in front of the
head lands where K projects it in each image, the right image shifted by fx * baseline / Z;
and the noise has DRCSim's spread."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.stereo.head_cameras import ImageNoise, StereoRenderer, camera_model
from tutorial_atlas_control.stereo.multisense import BASELINE_M, SIDES, intrinsics

#: A red sphere at (X forward, Y left, Z up) in the head frame, on a grey backdrop.
MARKER_M = (2.0, 0.25, -0.15)
MARKER_RADIUS_M = 0.05
SCENE = f"""<mujoco>
  <visual><headlight ambient="1 1 1" diffuse="0 0 0" specular="0 0 0"/></visual>
  <worldbody>
    <body name="head" pos="0 0 1.5"><freejoint/>
      <geom type="box" size="0.01 0.01 0.01" pos="-0.1 0 0" rgba="0.5 0.5 0.5 1"/>
    </body>
    <geom type="sphere" size="{MARKER_RADIUS_M}" rgba="1 0 0 1"
          pos="{MARKER_M[0]} {MARKER_M[1]} {1.5 + MARKER_M[2]}"/>
  </worldbody>
</mujoco>"""


@pytest.fixture(scope='module')
def renderer(tmp_path_factory: pytest.TempPathFactory) -> StereoRenderer:
    path = Path(tmp_path_factory.mktemp('scene')) / 'head.xml'
    path.write_text(SCENE)
    with StereoRenderer(camera_model(str(path))) as rendering:
        yield rendering


def marker_centre(image: np.ndarray) -> tuple[float, float]:
    """(u, v) of the red pixels' centroid, ROS's pixel convention (centres at integers)."""
    red = (image[..., 0] > 150) & (image[..., 1] < 60) & (image[..., 2] < 60)
    rows, cols = np.nonzero(red)
    assert rows.size > 100, 'the marker is not in the image'
    return float(cols.mean()), float(rows.mean())


def projected(side: str) -> tuple[float, float]:
    """Where the camera_info's P puts the marker. Both P map points of the LEFT optical
    frame (z forward, x right, y down; the right one through its Tx)."""
    left = SIDES[0].offset_m
    point = np.array([-(MARKER_M[1] - left[1]), -(MARKER_M[2] - left[2]),
                      MARKER_M[0] - left[0], 1.0])
    u, v, w = np.array(intrinsics(side).p).reshape(3, 4) @ point
    return u / w, v / w


@pytest.mark.parametrize('side', ['left', 'right'])
def test_marker_lands_where_camera_info_projects_it(renderer: StereoRenderer,
                                                    side: str) -> None:
    qpos = np.zeros(renderer.model.nq)
    qpos[2], qpos[3] = 1.5, 1.0  # the head's free joint at its place, unturned
    image = renderer.render_sides(qpos, [side])[side]
    assert image.shape == (800, 800, 3) and image.dtype == np.uint8
    u, v = marker_centre(image)
    expected_u, expected_v = projected(side)
    assert abs(u - expected_u) < 0.3 and abs(v - expected_v) < 0.3


def test_disparity_is_fx_baseline_over_depth(renderer: StereoRenderer) -> None:
    qpos = np.zeros(renderer.model.nq)
    qpos[2], qpos[3] = 1.5, 1.0
    images = renderer.render_sides(qpos, ['left', 'right'])
    disparity = marker_centre(images['left'])[0] - marker_centre(images['right'])[0]
    fx = intrinsics('left').fx
    assert disparity == pytest.approx(fx * BASELINE_M / MARKER_M[0], abs=0.3)


def test_noise_has_drcsims_spread_per_pixel_on_all_channels() -> None:
    grey = np.full((400, 400, 3), 128, np.uint8)
    noisy = ImageNoise(seed=3).apply(grey).astype(int) - 128
    assert noisy.std() == pytest.approx(0.007 * 255, rel=0.05)
    assert abs(noisy.mean()) < 0.05
    assert (noisy[..., 0] == noisy[..., 1]).all() and (noisy[..., 1] == noisy[..., 2]).all()
    black = ImageNoise(seed=3).apply(np.zeros((50, 50, 3), np.uint8))
    assert black.min() == 0 and black.max() > 0  # saturated, not wrapped around


def test_a_state_of_the_wrong_size_is_refused(renderer: StereoRenderer) -> None:
    with pytest.raises(ValueError, match='positions'):
        renderer.set_state(np.zeros(renderer.model.nq + 1))
