"""A walker's way over the hills: waypoints on the gentle ground between them.

Between gate_2 and gate_3 the course's hills rise 0.2-0.4 m over a metre or two; straight
lines from gate to gate cross ground up to 21 degrees steep under a sole, and Walk fell there
on every start tried (docs/vrc.md). Between the hills the ground is gentler: a way to gate_3
exists whose ground stays within about 11 degrees under the feet. Such a leg (course/legs.py's
`over_hills`) is planned when it begins, from where the walker is, on the course's heights
(terrain.py: the image the world's heightfield is made of).

The slope under a foot is the terrain's gradient over a sole's length (central differences
SOLE_SPAN_M apart); a cell of the GRID_M grid is free when the steepest slope within `reach_m`
of it (the feet's half stance and a sole's half width around the centre line) is at most
`steepest_deg`, and it keeps POST_CLEARANCE_M from every gate post. A* over the free cells
(grid_path.py) finds the shortest way; it is shortened to the corners between which straight
lines stay within SLACK_DEG more, and a corner inside the turning circle at the one before
it is dropped where a line past it stays within DROP_SLACK_DEG more: a walker turning in
strides cannot face a waypoint that lies within its turning circle (where neither line does,
the corner moves back along the way to it until the next one lies outside).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from scipy import ndimage

from tutorial_atlas_control.course.errors import CourseError
from tutorial_atlas_control.course.grid_path import (
    TURN_RADIUS_M,
    Cell,
    a_star,
    shortened,
    turnable,
)
from tutorial_atlas_control.course.rubble_way import distance_to_polygon, gate_posts
from tutorial_atlas_control.course.terrain import ground_under, terrain_heights

__all__ = ['GRID_M', 'REACH_M', 'STEEPEST_DEG', 'Heights', 'course_heights', 'gentle_path',
           'slope_deg']

#: Grid cell (m).
GRID_M = 0.05
#: Between the gradient's two samples (m): about a sole's length (0.26 m).
SOLE_SPAN_M = 0.3
#: The steepest ground (degrees) a way's cells may have within REACH_M of them. Walk went up
#: and down 8 degrees on every start tried and fell on the hills' 15-21 (docs/vrc.md); at 10
#: the way to gate_3 is 27.5 m long, at 11 22.4 m, at 9 there is none.
STEEPEST_DEG = 11.0
#: Around the centre line (m): half the feet's stance width and half a sole's width.
REACH_M = 0.15
#: The shortened way's straight lines may cross ground this much steeper (degrees).
SLACK_DEG = 1.0
#: A corner inside the turning circle (grid_path.TURN_RADIUS_M) at the one before is dropped
#: where the line past it (or, else, the line past the one before to it) crosses ground at
#: most DROP_SLACK_DEG steeper than the way.
DROP_SLACK_DEG = 3.0
#: The centre line keeps this far (m) from a gate post's side.
POST_CLEARANCE_M = 0.6
#: The grid reaches this far (m) beyond the start and the goal.
MARGIN_M = 3.0

Point = tuple[float, float]


#: The ground's heights (m) under world points (arrays of any shape).
Heights = Callable[[np.ndarray, np.ndarray], np.ndarray]


def course_heights(x_m: np.ndarray, y_m: np.ndarray) -> np.ndarray:
    """The course's terrain (its image) under world points."""
    return ground_under(terrain_heights(), x_m, y_m)


def slope_deg(x_m: np.ndarray, y_m: np.ndarray,
              heights: Heights = course_heights) -> np.ndarray:
    """The slope (degrees) of `heights` (the course's terrain by default) under a sole at
    each of the world points (any shape): the gradient by central differences SOLE_SPAN_M
    apart. Where `heights` does not know the ground (NaN: a map's unseen ground) that
    gradient counts as level: the way may go there, and a walker looks before it does
    (the nearest seen cell's height instead made cliffs between seen places and blocked
    every way over the hills)."""
    half = SOLE_SPAN_M / 2.0
    grade_x = (heights(x_m + half, y_m) - heights(x_m - half, y_m)) / SOLE_SPAN_M
    grade_y = (heights(x_m, y_m + half) - heights(x_m, y_m - half)) / SOLE_SPAN_M
    return np.degrees(np.arctan(np.hypot(np.nan_to_num(grade_x), np.nan_to_num(grade_y))))


def gentle_path(start: Point, goal: Point, steepest_deg: float = STEEPEST_DEG,
                reach_m: float = REACH_M, heights: Heights = course_heights
                ) -> tuple[Point, ...]:
    """Waypoints from `start` (excluded) to `goal` (the last one) over ground (`heights`: the
    course's terrain, or a walker's map of it) no steeper than `steepest_deg` within
    `reach_m` of the way (its straight lines SLACK_DEG more), clear of the gate posts. The
    start and the goal count as free.

    Raises:
        CourseError: no such way joins them.
    """
    if not (math.isfinite(steepest_deg) and 0.0 < steepest_deg < 90.0):
        raise CourseError(f'steepest_deg must be within (0, 90): {steepest_deg}')
    # The grid is the world's (cells on multiples of GRID_M), not the start's: a way from
    # places a few centimetres apart crosses the same cells.
    x0 = math.floor((min(start[0], goal[0]) - MARGIN_M) / GRID_M) * GRID_M
    y0 = math.floor((min(start[1], goal[1]) - MARGIN_M) / GRID_M) * GRID_M
    xs = np.arange(x0, max(start[0], goal[0]) + MARGIN_M + GRID_M / 2, GRID_M)
    ys = np.arange(y0, max(start[1], goal[1]) + MARGIN_M + GRID_M / 2, GRID_M)
    grid_x, grid_y = np.meshgrid(xs, ys, indexing='ij')
    radius = max(1, round(reach_m / GRID_M))
    di, dj = np.mgrid[-radius:radius + 1, -radius:radius + 1]
    steepest = ndimage.maximum_filter(slope_deg(grid_x, grid_y, heights),
                                      footprint=di ** 2 + dj ** 2 <= radius ** 2)
    clear = np.ones(grid_x.shape, dtype=bool)
    for post in gate_posts():
        clear &= distance_to_polygon(post, grid_x, grid_y) > POST_CLEARANCE_M

    def cell(point: Point) -> Cell:
        return int(round((point[0] - x0) / GRID_M)), int(round((point[1] - y0) / GRID_M))

    first, last = cell(start), cell(goal)
    free = clear & (steepest <= steepest_deg)
    free[first] = free[last] = True
    cells = a_star(free, first, last)
    if cells is None:
        raise CourseError(f'no way from ({start[0]:.2f}, {start[1]:.2f}) to '
                          f'({goal[0]:.2f}, {goal[1]:.2f}) keeps to ground within '
                          f'{steepest_deg:g} degrees')
    loose = clear & (steepest <= steepest_deg + SLACK_DEG)
    looser = clear & (steepest <= steepest_deg + DROP_SLACK_DEG)
    loose[first] = loose[last] = looser[first] = looser[last] = True
    kept = turnable(looser, shortened(loose, cells), TURN_RADIUS_M / GRID_M)
    return tuple((round(float(xs[i]), 3), round(float(ys[j]), 3)) for i, j in kept[1:-1]) \
        + (goal,)
