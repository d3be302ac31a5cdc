"""Values between a regular grid's vertices: the course's terrain image, the simulated
laser's heightfield and the laser's height map all interpolate their heights one way."""

from __future__ import annotations

import numpy as np

__all__ = ['grid_bilinear']


def grid_bilinear(values: np.ndarray, row: np.ndarray, col: np.ndarray) -> np.ndarray:
    """`values` (rows, cols) bilinear at fractional indices `row`, `col` within [0, rows - 1]
    and [0, cols - 1] (the callers clip or mask what lies outside: each says what the grid
    is outside itself). A point on the last row or column takes the cell before it."""
    rows, cols = values.shape
    r0 = np.minimum(np.floor(row).astype(int), rows - 2)
    c0 = np.minimum(np.floor(col).astype(int), cols - 2)
    fr, fc = row - r0, col - c0
    return ((values[r0, c0] * (1.0 - fc) + values[r0, c0 + 1] * fc) * (1.0 - fr)
            + (values[r0 + 1, c0] * (1.0 - fc) + values[r0 + 1, c0 + 1] * fc) * fr)
