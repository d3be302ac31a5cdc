"""A walker's way across the rubble: waypoints that keep its feet clear of every block.

Walk steps on the ground, not onto blocks: a leg through the rubble (course/legs.py's
`clear_of_blocks`) is planned when it begins, from where the walker is, around the blocks
the world description puts there (course/vrc_task_2.py's BLOCKS, or a variant's) and the
gates' posts. The ground is a grid of GRID_M cells over the leg's area; a cell is free when
its centre is more than `clearance_m` from every block's footprint (its 0.435 x 0.203 x
0.203 m envelope turned as it lies, seen from above) and every post. A* over the free cells
(8-connected, the straight-line distance as its estimate) finds the shortest grid path;
it is shortened to the few waypoints between which a straight line keeps the clearance less
SHORTCUT_SLACK_M, the ones a route of straight strides (walking/route.py) walks, and a corner
inside the turning circle at the one before is dropped or moved back (grid_path.turnable):
the walker turns its corners in strides. Whether its planned soles keep clear of the blocks
is sole_clearances_m's to say (offline/course_route.py's around_blocks asks it).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from scipy.spatial import cKDTree

from tutorial_atlas_control.course.errors import CourseError
from tutorial_atlas_control.course.grid_path import (
    TURN_RADIUS_M,
    a_star,
    cells_on_line,
    shortened,
    turnable,
)
from tutorial_atlas_control.course.vrc_task_2 import (
    BLOCK_ENVELOPE_M,
    GATE_POST_M,
    GATE_WIDTH_M,
    GATES,
    Block,
)

__all__ = ['CLEARANCE_M', 'GRID_M', 'SHORTCUT_SLACK_M', 'SOLE_CLEARANCE_M', 'block_corners',
           'block_footprint', 'footprints_within',
           'clear_path', 'distance_to_polygon', 'gate_posts', 'point_clearances_m',
           'sole_clearances_m']

#: Grid cell (m).
GRID_M = 0.05
#: The walker's centre line to a block's edge (m): half the feet's stance width (0.12) and half a
#: sole's (0.07), a swing's sway and the route's tracking, with room to spare (at 0.45 a walk
#: fell beside a block, 0.18 m from its left sole's edge).
CLEARANCE_M = 0.55
#: A shortened path's straight lines may pass this much (m) nearer than the clearance: the
#: grid path hugs the clearance's edge, and lines between its cells cut it by a cell or two.
SHORTCUT_SLACK_M = 0.1
#: A planned sole's edge to a block's footprint (m): what the way's straight lines leave a
#: sole (the clearance less the shortcut's slack and the centre line's 0.18 m reach to a
#: sole's outer edge: 0.27) less a grid cell and a little turn of the sole. A walk fell
#: beside a block 0.18 m from its sole's edge.
SOLE_CLEARANCE_M = 0.2
#: The grid reaches this far (m) beyond the start, the goal and the blocks between them.
MARGIN_M = 1.5

Point = tuple[float, float]


def _rotation(block: Block) -> np.ndarray:
    """Gazebo's roll, pitch, yaw (fixed axes x, y, z) as a rotation matrix."""
    cr, sr = math.cos(block.roll_rad), math.sin(block.roll_rad)
    cp, sp = math.cos(block.pitch_rad), math.sin(block.pitch_rad)
    cy, sy = math.cos(block.yaw_rad), math.sin(block.yaw_rad)
    return (np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
            @ np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
            @ np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]]))


def block_corners(block: Block) -> np.ndarray:
    """The world corners (8, 3) of the block's envelope as it lies (its frame at the
    envelope's bottom centre, turned by Gazebo's roll, pitch, yaw)."""
    half = np.array(BLOCK_ENVELOPE_M) / 2
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    return ((signs * half + (0.0, 0.0, half[2])) @ _rotation(block).T
            + (block.x_m, block.y_m, block.z_m))


def block_footprint(block: Block) -> np.ndarray:
    """The block's envelope seen from above: its convex hull's corners (k, 2),
    counter-clockwise."""
    return _hull(block_corners(block)[:, :2])


def footprints_within(a: Block, b: Block, gap_m: float) -> bool:
    """Whether the footprints of blocks `a` and `b` (block_footprint) overlap or come within
    `gap_m` of each other."""
    return _polygon_distance(block_footprint(a), block_footprint(b)) < gap_m


def _hull(points: np.ndarray) -> np.ndarray:
    """Andrew's monotone chain: the convex hull (counter-clockwise, no repeated point)."""
    ordered = sorted({(round(float(x), 9), round(float(y), 9)) for x, y in points})
    if len(ordered) < 3:
        return np.array(ordered)

    def chain(sequence: Sequence[Point]) -> list[Point]:
        kept: list[Point] = []
        for p in sequence:
            while len(kept) >= 2 and ((kept[-1][0] - kept[-2][0]) * (p[1] - kept[-2][1])
                                      - (kept[-1][1] - kept[-2][1]) * (p[0] - kept[-2][0])) <= 0:
                kept.pop()
            kept.append(p)
        return kept

    lower, upper = chain(ordered), chain(ordered[::-1])
    return np.array(lower[:-1] + upper[:-1])


def distance_to_polygon(polygon: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Distance (m) from points (x, y) to a convex counter-clockwise polygon (0 inside)."""
    inside = np.ones(np.shape(x), dtype=bool)
    distance = np.full(np.shape(x), np.inf)
    for (ax, ay), (bx, by) in zip(polygon, np.roll(polygon, -1, axis=0)):
        ex, ey = bx - ax, by - ay
        inside &= ex * (y - ay) - ey * (x - ax) >= 0.0
        t = np.clip(((x - ax) * ex + (y - ay) * ey) / (ex * ex + ey * ey), 0.0, 1.0)
        distance = np.minimum(distance, np.hypot(x - (ax + t * ex), y - (ay + t * ey)))
    return np.where(inside, 0.0, distance)


def gate_posts() -> list[np.ndarray]:
    """Every gate's two posts, seen from above."""
    half = GATE_POST_M[0] / 2
    square = np.array([[-half, -half], [half, -half], [half, half], [-half, half]])
    posts = []
    for gate in GATES:
        c, s = math.cos(gate.yaw_rad), math.sin(gate.yaw_rad)
        for side in (-1.0, 1.0):
            offset = side * (GATE_WIDTH_M / 2 - half)
            posts.append(square + (gate.x_m - s * offset, gate.y_m + c * offset))
    return posts


def clear_path(blocks: Sequence[Block], start: Point, goal: Point,
               clearance_m: float = CLEARANCE_M, obstacles: np.ndarray | None = None
               ) -> tuple[Point, ...]:
    """Waypoints from `start` (excluded) to `goal` (the last one) whose straight lines keep
    `clearance_m` from every block, gate post and point of `obstacles` ((n, 2) world x, y:
    what a walker's sensors took for obstacles) (from a start nearer one than that, the
    first goes straight to the nearest place that is not).

    Raises:
        CourseError: the goal is not clear, or no way joins them.
    """
    x0 = min(start[0], goal[0]) - MARGIN_M
    y0 = min(start[1], goal[1]) - MARGIN_M
    xs = np.arange(x0, max(start[0], goal[0]) + MARGIN_M + GRID_M / 2, GRID_M)
    ys = np.arange(y0, max(start[1], goal[1]) + MARGIN_M + GRID_M / 2, GRID_M)
    grid_x, grid_y = np.meshgrid(xs, ys, indexing='ij')
    nearest_m = np.full(grid_x.shape, np.inf)
    for polygon in [block_footprint(block) for block in blocks] + gate_posts():
        nearest_m = np.minimum(nearest_m, distance_to_polygon(polygon, grid_x, grid_y))
    if obstacles is not None and len(obstacles):
        distance, _ = cKDTree(np.asarray(obstacles)[:, :2]).query(
            np.stack((grid_x.ravel(), grid_y.ravel()), 1))
        nearest_m = np.minimum(nearest_m, distance.reshape(grid_x.shape))
    free = nearest_m > clearance_m

    def cell(point: Point) -> tuple[int, int]:
        return int(round((point[0] - x0) / GRID_M)), int(round((point[1] - y0) / GRID_M))

    if not free[cell(goal)]:
        raise CourseError(f'the goal ({goal[0]:.2f}, {goal[1]:.2f}) is within {clearance_m} m '
                          'of a block or a gate post')
    # A walker already nearer a block than the clearance first steps to the nearest free cell.
    first = cell(start)
    if not free[first]:
        spaces = np.argwhere(free)
        if not len(spaces):
            raise CourseError(f'nothing around ({start[0]:.2f}, {start[1]:.2f}) keeps '
                              f'{clearance_m} m from the blocks')
        nearest = spaces[np.argmin(np.hypot(*(spaces - first).T))]
        free[first] = True
        free[cells_on_line(first, (int(nearest[0]), int(nearest[1])))] = True
    cells = a_star(free, first, cell(goal))
    if cells is None:
        raise CourseError(f'no way from ({start[0]:.2f}, {start[1]:.2f}) to '
                          f'({goal[0]:.2f}, {goal[1]:.2f}) keeps {clearance_m} m from the blocks')
    looser = free | (nearest_m > clearance_m - SHORTCUT_SLACK_M)
    kept = turnable(looser, shortened(looser, cells), TURN_RADIUS_M / GRID_M)
    return tuple((round(float(xs[i]), 3), round(float(ys[j]), 3)) for i, j in kept[1:-1]) \
        + (goal,)


def _rectangle(x_m: float, y_m: float, yaw_rad: float,
               half_size_m: tuple[float, float]) -> np.ndarray:
    """A sole's corners (4, 2), counter-clockwise: its centre, heading and half sizes."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    local = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * half_size_m
    return local @ np.array([[c, s], [-s, c]]) + (x_m, y_m)


def _polygon_distance(a: np.ndarray, b: np.ndarray) -> float:
    """The distance (m) between two convex counter-clockwise polygons (0 when they overlap:
    no edge's normal separates them)."""
    for polygon, other in ((a, b), (b, a)):
        for start, end in zip(polygon, np.roll(polygon, -1, axis=0)):
            normal = np.array([end[1] - start[1], start[0] - end[0]])  # outward
            if np.all((other - start) @ normal > 0.0):
                return min(float(distance_to_polygon(b, a[:, 0], a[:, 1]).min()),
                           float(distance_to_polygon(a, b[:, 0], b[:, 1]).min()))
    return 0.0


def sole_clearances_m(soles: Sequence[tuple[float, float, float]], blocks: Sequence[Block],
                      half_size_m: tuple[float, float], obstacles: np.ndarray | None = None
                      ) -> np.ndarray:
    """How near (m) each sole ((x, y, yaw) of its centre; `half_size_m` its half length and
    width) comes to any block's footprint or point of `obstacles` ((n, 2) world x, y) (0: on
    one): a planned footstep's clearance."""
    footprints = [block_footprint(block) for block in blocks]
    points = np.empty((0, 2)) if obstacles is None else np.asarray(obstacles)[:, :2]
    nearest = []
    for sole in soles:
        rectangle = _rectangle(*sole, half_size_m)
        distances = [_polygon_distance(rectangle, footprint) for footprint in footprints]
        if len(points):
            distances.append(float(distance_to_polygon(rectangle, points[:, 0],
                                                       points[:, 1]).min()))
        nearest.append(min(distances, default=math.inf))
    return np.array(nearest)


def point_clearances_m(points: np.ndarray, blocks: Sequence[Block],
                       obstacles: np.ndarray | None = None) -> np.ndarray:
    """How near (m) each point ((n, 2) world x, y) comes to any block's footprint or point of
    `obstacles` (0: on a block)."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    nearest = np.full(len(points), np.inf)
    for footprint in (block_footprint(block) for block in blocks):
        nearest = np.minimum(nearest, distance_to_polygon(footprint, points[:, 0], points[:, 1]))
    if obstacles is not None and len(obstacles):
        distance, _ = cKDTree(np.asarray(obstacles)[:, :2]).query(points)
        nearest = np.minimum(nearest, distance)
    return nearest
