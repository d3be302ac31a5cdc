"""Where rays first meet a heightfield, without MuJoCo's heightfield ray test.

MuJoCo's ray test of a heightfield visits every cell of the rectangle a ray spans seen from
above: the laser's 720 rays of 30 m over the VRC course's 513 x 513 terrain took 480 ms a
scan. Here each ray is marched in MARCH_STEP_M steps over the heights, bilinear between the
vertices (MuJoCo's triangles lie within millimetres of that), and the first step under the
surface is bisected to BISECT_TOL_M.

Most of a scan's steps are far above the ground, so the march first looks at the rays in
segments of whole steps no longer than a tile of TILE_CELLS x TILE_CELLS cells: a segment
whose lower end is above the highest vertex of the tiles around its start cannot hold a
step under the surface, and its steps are not evaluated. The steps that are evaluated are
the same as a full march's, so the distances are a full march's bit for bit, only cheaper
(7 ms to about 2 ms a scan on the course; `test_heightfield_march.py`).

Compiled (src/atlas_heightfield.c, loaded by tutorial_atlas_control.native) the same march is
one call, its distances this numpy's bit for bit; `TAC_HEIGHTFIELD=python` for the numpy.
"""

from __future__ import annotations

import ctypes
import math

import mujoco
import numpy as np

from tutorial_atlas_control.grids import grid_bilinear
from tutorial_atlas_control.native import AtlasHeightfield, address, chosen_library

__all__ = ['BISECT_TOL_M', 'MARCH_STEP_M', 'TILE_CELLS', 'Heightfield']

#: A heightfield is marched in steps of this length (m; the course's cells are 0.195 m),
#: and its crossing bisected to this (m).
MARCH_STEP_M = 0.2
BISECT_TOL_M = 1e-4
#: Cells a side of the tiles whose highest vertices let the march skip a segment.
TILE_CELLS = 8
#: Set to `python` to march with numpy instead of the compiled library.
SWITCH_ENV = 'TAC_HEIGHTFIELD'


def _tile_maxima(heights: np.ndarray, tile: int) -> np.ndarray:
    """The highest vertex of each tile (its cells' corners), then of each tile's 3 x 3
    neighbourhood: a point within one tile's width of a tile lies under that figure."""
    rows, cols = heights.shape
    tile_rows, tile_cols = math.ceil((rows - 1) / tile), math.ceil((cols - 1) / tile)
    maxima = np.empty((tile_rows, tile_cols))
    for i in range(tile_rows):
        for j in range(tile_cols):
            maxima[i, j] = heights[i * tile:(i + 1) * tile + 1, j * tile:(j + 1) * tile + 1].max()
    padded = np.pad(maxima, 1, constant_values=-np.inf)
    return np.max([padded[1 + di:1 + di + tile_rows, 1 + dj:1 + dj + tile_cols]
                   for di in (-1, 0, 1) for dj in (-1, 0, 1)], axis=0)


class Heightfield:
    """One heightfield geom (unturned) as heights over a grid: where rays first meet it.

    `compiled`: None as SWITCH_ENV says (compiled unless `python`), False numpy's march."""

    def __init__(self, model: mujoco.MjModel, geom: int, compiled: bool | None = None) -> None:
        if not np.allclose(model.geom_quat[geom], (1.0, 0.0, 0.0, 0.0)):
            raise ValueError(f'heightfield geom {geom} is turned: the laser takes it upright')
        field = int(model.geom_dataid[geom])
        rows, cols = int(model.hfield_nrow[field]), int(model.hfield_ncol[field])
        start = int(model.hfield_adr[field])
        self.geom = geom
        self.half_x, self.half_y, top, _ = (float(v) for v in model.hfield_size[field])
        self.centre = np.array(model.geom_pos[geom], dtype=float)
        #: Heights (m, world z) of the vertices, row 0 at -y, column 0 at -x.
        self.heights = (self.centre[2] + top * np.asarray(
            model.hfield_data[start:start + rows * cols]).reshape(rows, cols))
        self.lowest, self.highest = float(self.heights.min()), float(self.heights.max())
        self._tile_highest = _tile_maxima(self.heights, TILE_CELLS)
        tile_width_m = TILE_CELLS * min(2.0 * self.half_x / (cols - 1),
                                        2.0 * self.half_y / (rows - 1))
        #: Steps a segment: its horizontal length within a tile's width.
        self.segment_steps = max(1, int(tile_width_m / MARCH_STEP_M))
        library = chosen_library(SWITCH_ENV, compiled)
        self._call = None if library is None else library.atlas_heightfield_distances
        self._struct = self._compiled_struct() if self._call is not None else None

    @property
    def compiled(self) -> bool:
        return self._call is not None

    def _compiled_struct(self) -> AtlasHeightfield:
        """The library's view of this field (its arrays are this object's, never replaced)."""
        self.heights = np.ascontiguousarray(self.heights)
        self._tile_highest = np.ascontiguousarray(self._tile_highest)
        rows, cols = self.heights.shape
        tile_rows, tile_cols = self._tile_highest.shape
        return AtlasHeightfield(
            address(self.heights, np.float64), address(self._tile_highest, np.float64),
            rows, cols, tile_rows, tile_cols, TILE_CELLS, self.segment_steps,
            float(self.centre[0]), float(self.centre[1]), self.half_x, self.half_y,
            self.lowest, self.highest, MARCH_STEP_M, BISECT_TOL_M)

    def height_m(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """The surface's height under world points (bilinear); -inf outside it."""
        rows, cols = self.heights.shape
        col = (x - self.centre[0] + self.half_x) / (2.0 * self.half_x) * (cols - 1)
        row = (y - self.centre[1] + self.half_y) / (2.0 * self.half_y) * (rows - 1)
        inside = (col >= 0.0) & (col <= cols - 1) & (row >= 0.0) & (row <= rows - 1)
        surface = grid_bilinear(self.heights, np.clip(row, 0.0, rows - 1.0),
                                np.clip(col, 0.0, cols - 1.0))
        return np.where(inside, surface, -np.inf)

    def tile_highest_m(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """The highest vertex within a tile's width around world points (outside the
        field: its nearest edge tile's, which is no lower than -inf there)."""
        rows, cols = self.heights.shape
        tile_rows, tile_cols = self._tile_highest.shape
        col = (x - self.centre[0] + self.half_x) / (2.0 * self.half_x) * (cols - 1)
        row = (y - self.centre[1] + self.half_y) / (2.0 * self.half_y) * (rows - 1)
        tile_col = np.clip(np.floor(col / TILE_CELLS), 0, tile_cols - 1).astype(int)
        tile_row = np.clip(np.floor(row / TILE_CELLS), 0, tile_rows - 1).astype(int)
        return self._tile_highest[tile_row, tile_col]

    def distances(self, origin: np.ndarray, rays: np.ndarray, range_m: float) -> np.ndarray:
        """Each ray's distance (m) to where it first goes below the surface, within
        `range_m`; -1 where it does not (0 for every ray from under the surface)."""
        if self._call is not None:
            return self._compiled_distances(origin, rays, range_m)
        result = np.full(len(rays), -1.0)
        if self.height_m(origin[:1], origin[1:2])[0] >= origin[2]:
            return np.zeros(len(rays))
        # How far a ray can meet the surface: not past its lowest point going down, never
        # going up or level from above its highest.
        reach = np.full(len(rays), float(range_m))
        falling = rays[:, 2] < 0.0
        reach[falling] = np.minimum(reach[falling],
                                    (origin[2] - self.lowest) / -rays[falling, 2])
        if origin[2] > self.highest:
            reach[~falling] = 0.0
        live = np.flatnonzero(reach > 0.0)
        if not len(live):
            return result
        steps = np.arange(MARCH_STEP_M, float(reach[live].max()) + MARCH_STEP_M, MARCH_STEP_M)
        first_step = self._first_steps_under(origin, rays[live], reach[live], steps)
        met = first_step >= 0
        first = first_step[met]
        near = np.where(first > 0, steps[np.maximum(first - 1, 0)], 0.0)
        distance = self.crossing_m(origin, rays[live[met]], near, steps[first])
        within = distance <= range_m
        result[live[met][within]] = distance[within]
        return result

    def _compiled_distances(self, origin: np.ndarray, rays: np.ndarray, range_m: float
                            ) -> np.ndarray:
        """distances() as one call into the library."""
        origin = np.ascontiguousarray(origin, dtype=np.float64)
        rays = np.ascontiguousarray(rays, dtype=np.float64).reshape(-1, 3)
        result = np.empty(len(rays))
        if self._call(ctypes.byref(self._struct), address(origin, np.float64),
                      address(rays, np.float64), len(rays), float(range_m),
                      address(result, np.float64)) != 0:
            raise MemoryError('the heightfield march ran out of memory')
        return result

    def crossing_m(self, origin: np.ndarray, rays: np.ndarray, near: np.ndarray,
                   far: np.ndarray) -> np.ndarray:
        """Where each ray crosses under the surface (m along it), bisected to BISECT_TOL_M
        between a distance above it (`near`) and one under it (`far`)."""
        while far.size and float((far - near).max()) > BISECT_TOL_M:
            middle = 0.5 * (near + far)
            at = origin + middle[:, None] * rays
            under = at[:, 2] <= self.height_m(at[:, 0], at[:, 1])
            far = np.where(under, middle, far)
            near = np.where(under, near, middle)
        return 0.5 * (near + far)

    def _first_steps_under(self, origin: np.ndarray, rays: np.ndarray, reach: np.ndarray,
                           steps: np.ndarray) -> np.ndarray:
        """Each ray's first step (an index into `steps`) at or under the surface and
        within its reach (plus a step), -1 where none is: a full march's answer, looking
        only at the segments the tiles do not rule out."""
        per = self.segment_steps
        segments = math.ceil(len(steps) / per)
        segment_start = np.concatenate(([0.0], steps[per - 1::per]))[:segments]
        segment_end = steps[np.minimum(np.arange(segments) * per + per - 1, len(steps) - 1)]
        start_points = origin + segment_start[:, None, None] * rays  # (segments, rays, 3)
        lowest_z = np.minimum(start_points[..., 2], origin[2] + segment_end[:, None] * rays[:, 2])
        candidate = ((lowest_z <= self.tile_highest_m(start_points[..., 0], start_points[..., 1]))
                     & (segment_start[:, None] <= reach + MARCH_STEP_M))
        segment, ray = np.nonzero(candidate)
        index = segment[:, None] * per + np.arange(per)  # (candidates, per) into steps
        valid = index < len(steps)
        index = np.minimum(index, len(steps) - 1)
        at = steps[index]
        points = origin + at[..., None] * rays[ray][:, None, :]
        under = (valid & (points[..., 2] <= self.height_m(points[..., 0], points[..., 1]))
                 & (at <= reach[ray][:, None] + MARCH_STEP_M))
        hit = under.any(axis=1)
        first = np.full(len(rays), len(steps))
        np.minimum.at(first, ray[hit], index[hit, np.argmax(under[hit], axis=1)])
        return np.where(first < len(steps), first, -1)
