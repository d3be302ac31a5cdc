"""The course as a walker's legs: the waypoints from each gate to the next.

A course walker (cli/vrc_walker.py, offline/course_route.py) walks one leg at a time, each
planned again from where the feet are once Stand has held LEG_PAUSE_S after the last one.
The legs keep clear of what is not ground to walk on: from the pen east through gate_0 to
x 3.2, 1.3 m clear of the pen's east wall (on a route turning north at x 2.5 the pelvis came
within 0.5-0.6 m of it and two landings fell 17 cm east of their steps: docs/vrc.md), north
past the wall's end, then to gate_1 (its feet stopping 5 cm past the gate's line, short of
the mud pit's ramp), through the pit to gate_2, over the hills to gate_3 (a way on the gentle
ground between them, planned when that leg begins: hill_way.py), and across the rubble to
gate_4 (a way around the blocks, planned so too: rubble_way.py). A
walker that starts elsewhere (one of the later starts) begins with the
nearest gate still ahead of it, walking that leg from its waypoint nearest the walker.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from tutorial_atlas_control.course.errors import CourseError
from tutorial_atlas_control.course.hill_way import gentle_path
from tutorial_atlas_control.course.rubble_way import clear_path
from tutorial_atlas_control.course.vrc_task_2 import GATES, Block, Gate

__all__ = ['COURSE_LEGS', 'LEG_PAUSE_S', 'Leg', 'leg_waypoints', 'legs_ahead']

#: Stand holds this long (s of sim time) between one leg's end and the next one's first
#: WALK: the catch after a walk settles, and a bag's walks stay apart (its analysis tells
#: one walk's steps from the next by the behaviour's changes; a next WALK within the same
#: millisecond fell into the last walk's window).
LEG_PAUSE_S = 1.0


@dataclass(frozen=True)
class Leg:
    """The waypoints (world x, y) to walk through to pass `gate`, the last one past it;
    `clear_of_blocks`: a leg across the rubble, whose way to its last waypoint is planned
    around the blocks when it begins (leg_waypoints); `over_hills`: a leg whose way to its
    last waypoint is planned on the gentle ground between the hills so."""

    gate: str
    waypoints: tuple[tuple[float, float], ...]
    clear_of_blocks: bool = False
    over_hills: bool = False


#: The course from the pen's start, gate by gate, in scoring order.
COURSE_LEGS: tuple[Leg, ...] = (
    Leg('gate_0', ((1.6, -38.0),)),
    Leg('gate_1', ((3.2, -38.0), (3.2, -31.0), (0.5, -24.5), (0.5, -21.95))),
    Leg('gate_2', ((0.5, -10.0),)),
    Leg('gate_3', ((6.0, 7.0),), over_hills=True),
    Leg('gate_4', ((6.0, 18.5),), clear_of_blocks=True),
)


def _ahead(gate: Gate, x_m: float, y_m: float) -> bool:
    """Whether (x, y) is still on the near side of `gate` (its line crossed along its yaw)."""
    along = (x_m - gate.x_m) * math.cos(gate.yaw_rad) + (y_m - gate.y_m) * math.sin(gate.yaw_rad)
    return along < 0.0


def legs_ahead(x_m: float, y_m: float, to_gate: str = GATES[-1].name) -> tuple[Leg, ...]:
    """The legs a walker at (x, y) walks to pass `to_gate`: from the nearest gate still ahead
    of it, its leg from the waypoint nearest the walker; none when `to_gate` is behind it.

    Raises:
        CourseError: `to_gate` is not a gate, or (x, y) is not finite.
    """
    names = [gate.name for gate in GATES]
    if to_gate not in names:
        raise CourseError(f'{to_gate!r} is not a gate of the course ({", ".join(names)})')
    if not (math.isfinite(x_m) and math.isfinite(y_m)):
        raise CourseError(f'a walker at ({x_m}, {y_m}) is nowhere')
    last = names.index(to_gate)
    ahead = [index for index, gate in enumerate(GATES[:last + 1]) if _ahead(gate, x_m, y_m)]
    if not ahead:
        return ()
    first = min(ahead, key=lambda index: math.hypot(GATES[index].x_m - x_m,
                                                   GATES[index].y_m - y_m))
    legs = list(COURSE_LEGS[first:last + 1])
    waypoints = legs[0].waypoints
    nearest = min(range(len(waypoints)),
                  key=lambda index: math.hypot(waypoints[index][0] - x_m,
                                               waypoints[index][1] - y_m))
    legs[0] = replace(legs[0], waypoints=waypoints[nearest:])
    return tuple(legs)


def rest_of_leg(leg: Leg, start_xy: tuple[float, float], now_xy: tuple[float, float]) -> Leg:
    """The leg as still to walk from `now_xy`, having begun at `start_xy`: the waypoints
    after the line of its route (start, waypoint, ...) nearest `now_xy` (a walker stopping
    partway, to look again, would otherwise plan from its first waypoint again)."""
    route = np.array([start_xy, *leg.waypoints])
    here = np.asarray(now_xy, dtype=float)
    starts, ends = route[:-1], route[1:]
    along = ends - starts
    length2 = np.maximum(np.sum(along * along, axis=1), 1e-12)
    t = np.clip(np.sum((here - starts) * along, axis=1) / length2, 0.0, 1.0)
    distance = np.hypot(*(starts + t[:, None] * along - here).T)
    return replace(leg, waypoints=leg.waypoints[int(np.argmin(distance)):])


def leg_waypoints(leg: Leg, x_m: float, y_m: float, blocks: Sequence[Block],
                  obstacles: np.ndarray | None = None) -> tuple[tuple[float, float], ...]:
    """The waypoints a walker at (x, y) walks for `leg`: its own, across the rubble a way
    around `blocks` and the points of `obstacles` (clear_path) to its last one, or over the
    hills a way on their gentle ground (gentle_path, on the course's terrain).

    Raises:
        CourseError: no way around the blocks, or none over gentle ground.
    """
    if leg.clear_of_blocks:
        return clear_path(blocks, (x_m, y_m), leg.waypoints[-1], obstacles=obstacles)
    if leg.over_hills:
        return gentle_path((x_m, y_m), leg.waypoints[-1])
    return leg.waypoints
