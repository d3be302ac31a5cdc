"""The ground's heights as the head's laser sees them: scans and the laser frame's world pose
-> points -> a world-anchored grid of ground heights a course walker can plan its steps on.

A scan's ranges (REP 117: only finite ones are returns) are placed in the world by the pose
of head_hokuyo_frame at the scan's time (on a robot: /tf; offline: the simulator's `head`
body, frames.py and the spindle's angle). Points are kept, not cells: the grid is computed
again from all of them when it is next asked for after new scans (a walker asks once a leg),
so each cell's height is a robust statistic of every point in it:
- points near the robot are dropped (a cylinder of `self_radius_m` around the pelvis: its
  legs, arms and feet are not ground; the ground there was seen from behind before);
- points farther than `max_distance_m` from the laser are dropped (few, grazing, noisy),
  and those more than `overhead_m` over it: overhead, what the robot walks under (the
  gates' bars were walls across the rubble's way);
- a cell's height is the median (`percentile`) of its points' heights, given `min_hits`
  of them: the noise averages (a low percentile biased it 4 mm low on the course's floor);
- a cell whose top (`top_percentile` of its points) stands more than `step_reach_m` over
  the lowest cell within `obstacle_window_m`, a step (a rise of that much from one cell to
  the next) within that window too, is an obstacle (a block, a wall, a gate post, or
  ground beside one with its side's points in it), not ground: neither known nor used; a
  ramp, however long, has no step (without that test the pit's 22-degree ramps were
  obstacles);
- a ground cell without enough points, next to known ones (up to `fill_cells` away), takes
  their mean: the laser's lines lie a few cells apart a few metres out;
- the known cells are smoothed by a Gaussian of `smooth_m` over known ground: a footstep
  planner's flatness test under a sole (1 cm: walking/ground_strides.py) read the cells'
  noise as bends and broke the pen's even strides up.
`height_m(x, y)` is bilinear between the four cell centres around the point when all four
are known ground, NaN otherwise; `nearest_m` the nearest known cell's height (a planner's
fallback for ground it has not seen). No ROS, no MuJoCo.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from tutorial_atlas_control.grids import grid_bilinear

__all__ = ['GroundGrid', 'HeightMap', 'HeightMapSpec', 'ground_grid', 'scan_points']

#: A cell and its eight neighbours (sums by correlation are exact: no running sums).
_NEIGHBOURS = np.ones((3, 3))


@dataclass(frozen=True)
class HeightMapSpec:
    """How scans become ground heights (ours; measured on the VRC course: docs/sensors.md)."""

    cell_m: float = 0.1
    percentile: float = 50.0
    top_percentile: float = 90.0
    min_hits: int = 2
    self_radius_m: float = 0.5
    max_distance_m: float = 12.0
    overhead_m: float = 0.3
    step_reach_m: float = 0.1
    obstacle_window_m: float = 0.6
    fill_cells: int = 2
    smooth_m: float = 0.1

    def __post_init__(self) -> None:
        positive = (self.cell_m, self.max_distance_m, self.step_reach_m, self.obstacle_window_m)
        if not all(math.isfinite(v) and v > 0.0 for v in positive) \
                or not 0.0 <= self.percentile <= self.top_percentile <= 100.0 \
                or self.min_hits < 1 \
                or self.self_radius_m < 0.0 or self.fill_cells < 0 \
                or not (math.isfinite(self.smooth_m) and self.smooth_m >= 0.0):
            raise ValueError(f'a height map needs positive cells, reach and ranges: {self}')


def scan_points(origin: np.ndarray, rotation: np.ndarray, angles: np.ndarray,
                ranges: np.ndarray) -> np.ndarray:
    """The world points (n, 3) of a planar scan's finite ranges: rays at `angles` (rad) in
    the x-y plane of a frame at `origin` turned by `rotation` (frame to world)."""
    ranges = np.asarray(ranges, dtype=float)
    hit = np.isfinite(ranges)
    local = np.stack((np.cos(angles[hit]), np.sin(angles[hit]), np.zeros(int(hit.sum()))), 1)
    return np.asarray(origin, dtype=float) + (local @ np.asarray(rotation).T) * ranges[hit, None]


@dataclass(frozen=True)
class GroundGrid:
    """The grid: cell (row, col) is centred at (x0 + col * cell, y0 + row * cell);
    `heights` (m, NaN where not known ground), `hits` (points per cell), `obstacle`."""

    x0_m: float
    y0_m: float
    cell_m: float
    heights: np.ndarray
    hits: np.ndarray
    obstacle: np.ndarray

    @property
    def known(self) -> np.ndarray:
        return np.isfinite(self.heights)

    def obstacle_xy(self) -> np.ndarray:
        """The obstacle cells' centres (n, 2; world x, y)."""
        rows, cols = np.nonzero(self.obstacle)
        return np.stack((self.x0_m + cols * self.cell_m, self.y0_m + rows * self.cell_m), 1)

    def index(self, x_m: np.ndarray, y_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The fractional (row, col) of world points."""
        return ((np.asarray(y_m, dtype=float) - self.y0_m) / self.cell_m,
                (np.asarray(x_m, dtype=float) - self.x0_m) / self.cell_m)

    def bilinear(self, x_m: np.ndarray, y_m: np.ndarray) -> np.ndarray:
        """Heights under world points, bilinear between known cells; NaN elsewhere."""
        row, col = self.index(x_m, y_m)
        rows, cols = self.heights.shape
        inside = (row >= 0.0) & (col >= 0.0) & (row < rows - 1) & (col < cols - 1)
        value = grid_bilinear(self.heights, np.where(inside, row, 0.0),
                              np.where(inside, col, 0.0))
        return np.where(inside, value, np.nan)


class HeightMap:
    """Ground heights from laser scans, world-anchored, updated as scans come."""

    def __init__(self, spec: HeightMapSpec | None = None) -> None:
        self.spec = spec or HeightMapSpec()
        self._chunks: list[np.ndarray] = []
        self._points = np.empty((0, 3))
        self._grid: GroundGrid | None = None
        self._nearest: tuple[np.ndarray, np.ndarray] | None = None
        self.scans = 0

    @property
    def points(self) -> np.ndarray:
        """Every point kept so far (n, 3)."""
        if self._chunks:
            self._points = np.concatenate([self._points, *self._chunks])
            self._chunks = []
        return self._points

    def add_scan(self, origin: np.ndarray, rotation: np.ndarray, angles: np.ndarray,
                 ranges: np.ndarray, robot_xy: tuple[float, float] | None = None) -> int:
        """One scan (scan_points' arguments) taken with the robot's pelvis at `robot_xy`
        (None: no self filter); how many of its points were kept."""
        points = scan_points(origin, rotation, angles, ranges)
        near = np.linalg.norm(points - np.asarray(origin), axis=1) <= self.spec.max_distance_m
        near &= points[:, 2] <= origin[2] + self.spec.overhead_m
        if robot_xy is not None:
            away = np.hypot(points[:, 0] - robot_xy[0], points[:, 1] - robot_xy[1])
            near &= away > self.spec.self_radius_m
        self.scans += 1
        return self.add_points(points[near])

    def add_points(self, points: np.ndarray) -> int:
        """World points (n, 3) taken as they are; how many."""
        if len(points):
            self._chunks.append(np.asarray(points, dtype=float))
            self._grid = self._nearest = None
        return len(points)

    @property
    def grid(self) -> GroundGrid:
        """The grid of every point so far (computed again after new points)."""
        if self._grid is None:
            self._grid = ground_grid(self.points, self.spec)
        return self._grid

    def height_m(self, x_m: float, y_m: float) -> float:
        """The ground's height under (x, y): bilinear over known ground, NaN where unknown."""
        return float(self.grid.bilinear(np.asarray(x_m), np.asarray(y_m)))

    def _nearest_cells(self) -> tuple[np.ndarray | None, np.ndarray | None]:
        """Each cell's nearest known cell (row and column index grids), or (None, None)."""
        known = self.grid.known
        if not known.any():
            return None, None
        if self._nearest is None:
            _, index = ndimage.distance_transform_edt(~known, return_indices=True)
            self._nearest = (index[0], index[1])
        return self._nearest

    def nearest_m(self, x_m: float, y_m: float) -> tuple[float, float]:
        """The height of the known ground cell nearest (x, y), and how far it is (m); (NaN,
        inf) when nothing is known."""
        grid = self.grid
        nearest_rows, nearest_cols = self._nearest_cells()
        if nearest_rows is None or nearest_cols is None:
            return math.nan, math.inf
        rows, cols = nearest_rows.shape
        row, col = grid.index(x_m, y_m)
        r = min(max(round(float(row)), 0), rows - 1)
        c = min(max(round(float(col)), 0), cols - 1)
        nr, nc = int(nearest_rows[r, c]), int(nearest_cols[r, c])
        distance = math.hypot(x_m - (grid.x0_m + nc * grid.cell_m),
                              y_m - (grid.y0_m + nr * grid.cell_m))
        return float(grid.heights[nr, nc]), distance


def _cell_statistics(points: np.ndarray, spec: HeightMapSpec
                     ) -> tuple[float, float, np.ndarray, np.ndarray, np.ndarray]:
    """(x0, y0, the cells' percentile of z and their top percentile (NaN without
    min_hits), hits per cell)."""
    cell = spec.cell_m
    col = np.floor(points[:, 0] / cell + 0.5).astype(np.int64)
    row = np.floor(points[:, 1] / cell + 0.5).astype(np.int64)
    c_min, r_min = int(col.min()), int(row.min())
    shape = (int(row.max()) - r_min + 2, int(col.max()) - c_min + 2)
    key = (row - r_min) * shape[1] + (col - c_min)
    order = np.lexsort((points[:, 2], key))
    key, z = key[order], points[order, 2]
    cells, first, counts = np.unique(key, return_index=True, return_counts=True)
    hits = np.zeros(shape[0] * shape[1], dtype=np.int64)
    hits[cells] = counts
    enough = counts >= spec.min_hits
    levels = []
    for percentile in (spec.percentile, spec.top_percentile):
        at = first + np.floor((counts - 1) * percentile / 100.0).astype(np.int64)
        level = np.full(shape[0] * shape[1], np.nan)
        level[cells[enough]] = z[at[enough]]
        levels.append(level.reshape(shape))
    return c_min * cell, r_min * cell, levels[0], levels[1], hits.reshape(shape)


def ground_grid(points: np.ndarray, spec: HeightMapSpec) -> GroundGrid:
    """The grid of `points`: cells' heights, obstacles taken out, small holes filled."""
    if not len(points):
        empty = np.full((2, 2), np.nan)  # bilinear reads a cell and the next
        return GroundGrid(0.0, 0.0, spec.cell_m, empty, np.zeros((2, 2), dtype=np.int64),
                          np.zeros((2, 2), dtype=bool))
    x0, y0, low, top, hits = _cell_statistics(points, spec)
    seen = np.isfinite(low)
    window = 2 * round(spec.obstacle_window_m / spec.cell_m / 2) + 1
    floor = np.where(seen, low, np.inf)
    lowest = ndimage.minimum_filter(floor, size=window, mode='nearest')
    # A step: the top over a neighbour's ground by more than a step's reach within one cell
    # (45 degrees at 5 cm cells; the pit's 22-degree ramps rise 4 cm over two cells).
    rise = np.where(seen, top, -np.inf) - ndimage.minimum_filter(floor, size=3, mode='nearest')
    near_step = ndimage.maximum_filter(rise > spec.step_reach_m, size=window, mode='nearest')
    obstacle = seen & (top - lowest > spec.step_reach_m) & near_step
    ground = np.where(seen & ~obstacle, low, np.nan)
    heights = _smoothed(_filled(ground, obstacle, spec.fill_cells), spec.smooth_m / spec.cell_m)
    return GroundGrid(x0, y0, spec.cell_m, heights, hits, obstacle)


def _smoothed(heights: np.ndarray, sigma_cells: float) -> np.ndarray:
    """The known cells' heights averaged with their known neighbours' by a Gaussian of
    `sigma_cells` (0: as they are): a planner's flatness test under a sole reads the ground,
    not the cells' noise."""
    if sigma_cells <= 0.0:
        return heights
    known = np.isfinite(heights)
    total = ndimage.gaussian_filter(np.where(known, heights, 0.0), sigma_cells,
                                    mode='constant', truncate=2.0)
    weight = ndimage.gaussian_filter(known.astype(float), sigma_cells, mode='constant',
                                     truncate=2.0)
    return np.where(known, total / np.where(known, weight, 1.0), np.nan)


def _filled(heights: np.ndarray, obstacle: np.ndarray, cells: int) -> np.ndarray:
    """`heights` with unknown cells (not obstacles) next to known ones given the mean of
    their known neighbours, `cells` times over (each pass reaches one cell further)."""
    for _ in range(cells):
        known = np.isfinite(heights)
        total = ndimage.correlate(np.where(known, heights, 0.0), _NEIGHBOURS, mode='constant')
        count = ndimage.correlate(known.astype(float), _NEIGHBOURS, mode='constant')
        hole = ~known & ~obstacle & (count > 0.5)
        if not hole.any():
            break
        heights = np.where(hole, total / np.maximum(count, 1.0), heights)
    return heights
