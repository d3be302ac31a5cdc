"""The support polygon: the convex hull of the sole corners in contact, and keeping a
desired centre of pressure inside it (a pressure centre cannot leave the feet).

In plain floats: polygons of a few vertices, every 1 ms tick, where numpy's per-call cost
would dominate.
"""

from __future__ import annotations

import math

import numpy as np


def convex_hull(points_xy: np.ndarray) -> np.ndarray:
    """The convex hull of (n, 2) points, counter-clockwise, without collinear points
    (Andrew's monotone chain)."""
    points = sorted(set(map(tuple, np.asarray(points_xy, dtype=np.float64).tolist())))
    if len(points) < 3:
        return np.array(points, dtype=np.float64).reshape(-1, 2)

    def chain(ordered: list[tuple[float, float]]) -> list[tuple[float, float]]:
        hull: list[tuple[float, float]] = []
        for x, y in ordered:
            while len(hull) >= 2:
                (ox, oy), (ax, ay) = hull[-2], hull[-1]
                if (ax - ox) * (y - oy) - (ay - oy) * (x - ox) > 0.0:
                    break
                hull.pop()
            hull.append((x, y))
        return hull

    lower, upper = chain(points), chain(points[::-1])
    return np.array(lower[:-1] + upper[:-1], dtype=np.float64)


Point = tuple[float, float]


def _inward_lines(vertices: list[Point]) -> list[tuple[float, float, float]]:
    """(n_x, n_y, offset) of each edge i (vertex i to i + 1): n the inward unit normal,
    n . p - offset the signed distance of p to the edge's line."""
    lines = []
    for (ax, ay), (bx, by) in zip(vertices, vertices[1:] + vertices[:1]):
        nx, ny = ay - by, bx - ax
        length = math.hypot(nx, ny)
        nx, ny = nx / length, ny / length
        lines.append((nx, ny, nx * ax + ny * ay))
    return lines


def _distance(lines: list[tuple[float, float, float]], x: float, y: float) -> float:
    return min(nx * x + ny * y - offset for nx, ny, offset in lines)


def signed_distance(polygon: np.ndarray, point_xy: np.ndarray) -> float:
    """The distance (m) from `point_xy` to the nearest edge line of the counter-clockwise
    convex `polygon`: positive inside, negative outside (then a lower bound of the
    distance to the polygon)."""
    x, y = (float(v) for v in point_xy)
    return _distance(_inward_lines(np.asarray(polygon).tolist()), x, y)


def inside(polygon: np.ndarray, point_xy: np.ndarray, margin_m: float = 0.0) -> bool:
    """Whether `point_xy` is inside the counter-clockwise `polygon`, at least `margin_m`
    from every edge."""
    return signed_distance(polygon, point_xy) >= margin_m


def _shrunk(vertices: list[Point], margin_m: float) -> list[Point]:
    if margin_m <= 0.0:
        return vertices
    count = len(vertices)
    cx, cy = sum(v[0] for v in vertices) / count, sum(v[1] for v in vertices) / count
    lines = _inward_lines(vertices)
    if _distance(lines, cx, cy) <= margin_m:
        return [(cx, cy)]
    # Vertex i is where the moved lines of edges i-1 and i meet (Cramer's rule).
    shrunk = []
    for (ax, ay, a_off), (bx, by, b_off) in zip(lines[-1:] + lines[:-1], lines):
        a_off, b_off = a_off + margin_m, b_off + margin_m
        det = ax * by - ay * bx
        shrunk.append(((a_off * by - b_off * ay) / det, (ax * b_off - bx * a_off) / det))
    return shrunk


def shrink(polygon: np.ndarray, margin_m: float) -> np.ndarray:
    """The convex `polygon` with every edge moved `margin_m` inwards; its centroid (1, 2)
    if the margin swallows it."""
    return np.array(_shrunk(np.asarray(polygon).tolist(), margin_m), dtype=np.float64)


class Region:
    """A convex polygon shrunk by a margin, prepared once for clamping points into it."""

    def __init__(self, polygon: np.ndarray, margin_m: float = 0.0) -> None:
        self.vertices = _shrunk(np.asarray(polygon).tolist(), margin_m)
        #: Each edge's (inward normal x, y, offset), edge i from vertex i to i + 1 (none for
        #: a region shrunk to a point).
        self.lines = _inward_lines(self.vertices) if len(self.vertices) >= 3 else []

    def clamp(self, point_xy: np.ndarray) -> np.ndarray:
        """`point_xy` if it is inside, else the region's nearest point."""
        x, y = (float(v) for v in point_xy)
        vertices = self.vertices
        if len(vertices) < 3:
            return np.array(vertices[0])
        if _distance(self.lines, x, y) >= 0.0:
            return np.array([x, y])
        best, best_d2 = (x, y), math.inf
        for (ax, ay), (bx, by) in zip(vertices, vertices[1:] + vertices[:1]):
            ex, ey = bx - ax, by - ay
            t = min(max(((x - ax) * ex + (y - ay) * ey) / (ex * ex + ey * ey), 0.0), 1.0)
            px, py = ax + t * ex, ay + t * ey
            d2 = (px - x) ** 2 + (py - y) ** 2
            if d2 < best_d2:
                best, best_d2 = (px, py), d2
        return np.array(best)


def clamp_into(polygon: np.ndarray, point_xy: np.ndarray, margin_m: float = 0.0) -> np.ndarray:
    """`point_xy` if it is inside the convex `polygon` shrunk by `margin_m`, else the
    nearest point of that shrunk polygon."""
    return Region(polygon, margin_m).clamp(point_xy)
