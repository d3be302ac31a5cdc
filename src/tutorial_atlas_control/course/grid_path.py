"""Shortest ways over a grid of the ground, for a walker's waypoints: A* over the free cells,
then shortened to the few straight lines a route of straight strides (walking/route.py)
walks, and its corners made ones a walker turning in strides can face (turnable).
rubble_way.py (around the blocks) and hill_way.py (over the gentle ground between the hills)
mark the free cells; a cell is a pair of indices into the grid, x first."""

from __future__ import annotations

import heapq
import math

import numpy as np

__all__ = ['TURN_RADIUS_M', 'Cell', 'a_star', 'cells_on_line', 'inside_turn', 'shortened',
           'turnable', 'turned_earlier', 'visible']

Cell = tuple[int, int]

#: A walker turning in strides turns on a circle of about this radius (m; route.py's turning
#: steps: 0.08 m each turning 0.2 rad make 0.4): a corner inside the circle from the one
#: before (as the walker arrives there) cannot be faced (turnable).
TURN_RADIUS_M = 0.45

_MOVES = [(di, dj, math.hypot(di, dj)) for di in (-1, 0, 1) for dj in (-1, 0, 1)
          if (di, dj) != (0, 0)]


def a_star(free: np.ndarray, start: Cell, goal: Cell) -> list[Cell] | None:
    """The shortest 8-connected path over free cells, start and goal included (None: no
    way joins them)."""
    def estimate(c: Cell) -> float:
        return math.hypot(c[0] - goal[0], c[1] - goal[1])

    cost = {start: 0.0}
    came: dict[Cell, Cell] = {}
    todo = [(estimate(start), start)]
    while todo:
        _, here = heapq.heappop(todo)
        if here == goal:
            path = [here]
            while path[-1] in came:
                path.append(came[path[-1]])
            return path[::-1]
        for di, dj, step in _MOVES:
            there = (here[0] + di, here[1] + dj)
            if not (0 <= there[0] < free.shape[0] and 0 <= there[1] < free.shape[1]) \
                    or not free[there]:
                continue
            new = cost[here] + step
            if new < cost.get(there, math.inf):
                cost[there], came[there] = new, here
                heapq.heappush(todo, (new + estimate(there), there))
    return None


def cells_on_line(a: Cell, b: Cell) -> tuple[np.ndarray, np.ndarray]:
    """The cells on the straight line a..b (indices into the grid)."""
    count = max(abs(b[0] - a[0]), abs(b[1] - a[1])) * 2 + 1
    return (np.rint(np.linspace(a[0], b[0], count)).astype(int),
            np.rint(np.linspace(a[1], b[1], count)).astype(int))


def visible(free: np.ndarray, a: Cell, b: Cell) -> bool:
    """Whether every cell on the straight line a..b is free."""
    return bool(free[cells_on_line(a, b)].all())


def shortened(free: np.ndarray, cells: list[Cell]) -> list[Cell]:
    """The path's corners: from each kept cell, the farthest cell still in straight sight."""
    kept = [cells[0]]
    here = 0
    while here < len(cells) - 1:
        far = len(cells) - 1
        while far > here + 1 and not visible(free, cells[here], cells[far]):
            far -= 1
        kept.append(cells[far])
        here = far
    return kept


def inside_turn(before: Cell, corner: Cell, after: Cell, radius: float) -> bool:
    """Whether `after` lies inside the turning circle at `corner` of a walker arriving there
    from `before`, on the side it turns to (`radius` in cells)."""
    heading = math.atan2(corner[1] - before[1], corner[0] - before[0])
    bearing = math.atan2(after[1] - corner[1], after[0] - corner[0])
    side = math.copysign(1.0, math.remainder(bearing - heading, math.tau))
    centre = (corner[0] - side * radius * math.sin(heading),
              corner[1] + side * radius * math.cos(heading))
    return math.dist(after, centre) < radius


def turnable(looser: np.ndarray, corners: list[Cell], radius: float) -> list[Cell]:
    """`corners` fit for a walker turning in strides on a circle of `radius` (cells): a
    corner inside the turning circle at the one before is dropped where the line from the
    one before to the one after stays on `looser` cells, else the one before it where the
    line past that one does, else that one is moved back along its run (turned_earlier)."""
    kept = list(corners)
    index = 2
    while index < len(kept):
        if not inside_turn(kept[index - 2], kept[index - 1], kept[index], radius):
            index += 1
        elif index + 1 < len(kept) and visible(looser, kept[index - 1], kept[index + 1]):
            del kept[index]
        elif visible(looser, kept[index - 2], kept[index]):
            del kept[index - 1]
            index = max(2, index - 1)
        else:
            kept[index - 1] = turned_earlier(looser, *kept[index - 2:index + 1], radius)
            index += 1
    return kept


def turned_earlier(looser: np.ndarray, before: Cell, corner: Cell, after: Cell,
                   radius: float) -> Cell:
    """`corner` moved back towards `before`, a cell at a time, to the first place from which
    `after` lies outside the turning circle and the line to it stays on `looser` cells (the
    corner itself when there is none)."""
    count = max(abs(corner[0] - before[0]), abs(corner[1] - before[1]))
    for k in range(1, count):
        earlier = (round(corner[0] + (before[0] - corner[0]) * k / count),
                   round(corner[1] + (before[1] - corner[1]) * k / count))
        if not inside_turn(before, earlier, after, radius) and visible(looser, earlier, after):
            return earlier
    return corner
