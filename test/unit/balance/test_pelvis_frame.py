"""stand.pelvis_frame, written out in floats (every tick of a Stand's take-over), has the very
bits of the product it replaced, yaw_rotation(yaw) @ the pitch about y, signs of zero
included: random headings and pitches, and the exact zeros, ±pi and the default pitch."""

from __future__ import annotations

import math

import numpy as np

from tutorial_atlas_control.balance.stand import pelvis_frame, yaw_rotation


def _product(yaw_rad: float, pitch_rad: float) -> np.ndarray:
    """The frame as it was made: numpy's cos and sin of the pitch, a 3 x 3 product."""
    c, s = np.cos(pitch_rad), np.sin(pitch_rad)
    return yaw_rotation(yaw_rad) @ np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def test_the_frame_is_the_product_bit_for_bit() -> None:
    rng = np.random.default_rng(61)
    angles = [(float(yaw), float(pitch)) for yaw, pitch in
              zip(rng.uniform(-4.0, 4.0, 5000), rng.normal(0.0, 0.3, 5000), strict=True)]
    angles += [(float(yaw), 0.0) for yaw in rng.uniform(-4.0, 4.0, 500)]
    angles += [(yaw, pitch) for yaw in (0.0, -0.0, math.pi, -math.pi, math.pi / 2, 1e-300)
               for pitch in (0.0, -0.0, 0.2, -0.2, 1e-300)]
    for yaw, pitch in angles:
        made = pelvis_frame(yaw, pitch)
        assert made.tobytes() == _product(yaw, pitch).tobytes(), (yaw, pitch)
    assert pelvis_frame(0.3).tobytes() == _product(0.3, 0.0).tobytes()
