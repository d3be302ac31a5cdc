"""grid_bilinear: the one bilinear the terrain image, the laser's heightfield and its height
map share."""

from __future__ import annotations

import numpy as np

from tutorial_atlas_control.grids import grid_bilinear


def test_vertices_are_exact_and_a_cell_is_bilinear_between_them() -> None:
    values = np.arange(12.0).reshape(3, 4) ** 2  # not a plane: bilinear, not planar, counts
    rows, cols = np.meshgrid(np.arange(3.0), np.arange(4.0), indexing='ij')
    assert np.array_equal(grid_bilinear(values, rows, cols), values)  # the last row and col too
    row, col = np.array([0.25, 1.5]), np.array([2.5, 0.75])
    by_hand = [(1 - fr) * ((1 - fc) * values[r, c] + fc * values[r, c + 1])
               + fr * ((1 - fc) * values[r + 1, c] + fc * values[r + 1, c + 1])
               for r, c, fr, fc in ((0, 2, 0.25, 0.5), (1, 0, 0.5, 0.75))]
    assert np.allclose(grid_bilinear(values, row, col), by_hand, rtol=0.0, atol=1e-12)


def test_a_plane_is_kept_anywhere_in_the_grid() -> None:
    rows, cols = np.meshgrid(np.arange(5.0), np.arange(7.0), indexing='ij')
    plane = 0.3 * rows - 0.7 * cols + 2.0
    rng = np.random.default_rng(3)
    row, col = rng.uniform(0.0, 4.0, 200), rng.uniform(0.0, 6.0, 200)
    assert np.allclose(grid_bilinear(plane, row, col), 0.3 * row - 0.7 * col + 2.0,
                       rtol=0.0, atol=1e-12)
