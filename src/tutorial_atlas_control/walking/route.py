"""Footsteps along a route of waypoints: what a course walker streams from gate to gate.

A route starts where the robot stands (its soles' midpoint and heading) and runs through
waypoints on the ground plane. The walker's centre line turns towards each waypoint in short
steps (at most `turn_step_rad` of heading a step, half of Walk's 0.4 rad limit between the
feet, each `turn_stride_m` long), taking the waypoint's bearing again after each, then goes
straight to it in equal strides of at most `stride_m`; at the end it turns to the final
heading, if one is given, and brings the trailing foot beside the leading one.
Each foot lands across the centre line from the other, `width_m` apart, as straight_steps
places them: step k's sole is the centre line's point after k moves, moved half the width
to its own side. The heights are the world's: the AtlasSimInterface puts every step on the
ground under it (asi/library.py's on_ground).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

from tutorial_atlas_control.walking.errors import WalkingError
from tutorial_atlas_control.walking.footsteps import (
    LEFT,
    RIGHT,
    STANCE_WIDTH_M,
    STEP_DURATION_S,
    Footstep,
    side_sign,
    wrap_angle,
)

__all__ = ['RouteGait', 'feet_origin', 'route_steps']

#: A waypoint this near the centre line's point (m) is reached: no move towards it.
REACHED_M = 1e-6
#: A waypoint not faced after this many turning steps is inside the turning circle.
MAX_TURNING_STEPS = 64


@dataclass(frozen=True)
class RouteGait:
    """How a route is walked (ours; the streamed gate_1 walk of docs/vrc.md used these)."""

    #: The longest straight stride (m): each foot lands this far ahead of the other.
    stride_m: float = 0.15
    #: The most the heading turns in one step (rad), and how long a turning step is (m;
    #: 0 turns in place).
    turn_step_rad: float = 0.2
    turn_stride_m: float = 0.08
    width_m: float = STANCE_WIDTH_M
    duration_s: float = STEP_DURATION_S

    def turning_in_place(self) -> RouteGait:
        """This gait with its turns in place: among obstacles, where a corner must be
        turned on the spot (a turning stride sweeps a circle)."""
        return replace(self, turn_stride_m=0.0)

    def __post_init__(self) -> None:
        numbers = (self.stride_m, self.turn_step_rad, self.width_m, self.duration_s)
        if not all(math.isfinite(value) and value > 0.0 for value in numbers) \
                or not (math.isfinite(self.turn_stride_m) and self.turn_stride_m >= 0.0):
            raise WalkingError(f'a route gait needs positive finite numbers (a turning '
                               f'stride of 0 turns in place): {self}')


def _turn(heading_rad: float, goal_rad: float, gait: RouteGait) -> list[tuple[float, float]]:
    """The moves (heading, length) turning from `heading_rad` to face `goal_rad` in equal
    parts of at most a step's turn."""
    turn = wrap_angle(goal_rad - heading_rad)
    count = math.ceil(abs(turn) / gait.turn_step_rad - 1e-9)
    return [(heading_rad + turn * (k + 1) / count, gait.turn_stride_m) for k in range(count)]


def _moves(start_xy: tuple[float, float], start_yaw_rad: float,
           waypoints: Sequence[tuple[float, float]], final_heading_rad: float | None,
           gait: RouteGait) -> list[tuple[float, float]]:
    """The centre line's moves (heading, length) through every waypoint: turning steps
    while the waypoint's bearing is more than a step's turn away (each moves the centre,
    so the bearing is taken again), then equal strides straight to it."""
    x, y = start_xy
    heading = start_yaw_rad
    moves: list[tuple[float, float]] = []
    for goal_x, goal_y in waypoints:
        if not (math.isfinite(goal_x) and math.isfinite(goal_y)):
            raise WalkingError(f'waypoint ({goal_x}, {goal_y}) is not finite')
        for _ in range(MAX_TURNING_STEPS):
            distance = math.hypot(goal_x - x, goal_y - y)
            turn = wrap_angle(math.atan2(goal_y - y, goal_x - x) - heading)
            if distance < REACHED_M or abs(turn) <= gait.turn_step_rad:
                break
            heading += math.copysign(gait.turn_step_rad, turn)
            x += gait.turn_stride_m * math.cos(heading)
            y += gait.turn_stride_m * math.sin(heading)
            moves.append((heading, gait.turn_stride_m))
        else:
            raise WalkingError(f'waypoint ({goal_x}, {goal_y}) lies inside the turning circle '
                               f'from ({x:.3f}, {y:.3f}): no step faces it')
        distance = math.hypot(goal_x - x, goal_y - y)
        if distance < REACHED_M:
            continue
        heading = math.atan2(goal_y - y, goal_x - x)
        count = math.ceil(distance / gait.stride_m - 1e-9)
        moves += [(heading, distance / count)] * count
        x, y = goal_x, goal_y
    if final_heading_rad is not None:
        moves += _turn(heading, final_heading_rad, gait)
    return moves


def route_steps(start_xy: tuple[float, float], start_yaw_rad: float,
                waypoints: Sequence[tuple[float, float]], gait: RouteGait | None = None,
                final_heading_rad: float | None = None) -> list[Footstep]:
    """The steps (indices from 1) walking from feet side by side at `start_xy` facing
    `start_yaw_rad` through `waypoints` (world x, y), the last step bringing the feet side
    by side. The first foot to move is the one on the side of the first turn (left when
    the route starts straight).

    Raises:
        WalkingError: no waypoint, a waypoint not finite, or a route with no move.
    """
    gait = gait or RouteGait()
    if not waypoints:
        raise WalkingError('a route needs at least one waypoint')
    moves = _moves(start_xy, start_yaw_rad, waypoints, final_heading_rad, gait)
    if not moves:
        raise WalkingError(f'the route from {start_xy} goes nowhere: every waypoint is there')
    first_turn = wrap_angle(moves[0][0] - start_yaw_rad)
    first_foot = RIGHT if first_turn < 0.0 else LEFT
    steps = []
    x, y = start_xy
    heading = start_yaw_rad
    for k, (heading, length) in enumerate(moves, start=1):
        x += length * math.cos(heading)
        y += length * math.sin(heading)
        steps.append(_foot_at(k, first_foot if k % 2 == 1 else 1 - first_foot, x, y, heading,
                              gait))
    last = len(moves) + 1
    steps.append(_foot_at(last, first_foot if last % 2 == 1 else 1 - first_foot, x, y, heading,
                          gait))
    return steps


def _foot_at(index: int, foot: int, x_m: float, y_m: float, heading_rad: float,
             gait: RouteGait) -> Footstep:
    """Step `index` of `foot`: half the width to its side of the centre line's point."""
    half = side_sign(foot) * gait.width_m / 2
    return Footstep(index, foot, x_m - half * math.sin(heading_rad),
                    y_m + half * math.cos(heading_rad), wrap_angle(heading_rad),
                    gait.duration_s)


def feet_origin(left: tuple[float, float, float],
                right: tuple[float, float, float]) -> tuple[tuple[float, float], float]:
    """Where a route starts from feet at `left` and `right` ((x, y, yaw), world): their
    midpoint and mean heading (the mean taken across the short way between the two yaws)."""
    heading = wrap_angle(left[2] + 0.5 * wrap_angle(right[2] - left[2]))
    return (0.5 * (left[0] + right[0]), 0.5 * (left[1] + right[1])), heading
