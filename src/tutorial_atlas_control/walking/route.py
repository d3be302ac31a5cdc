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
ground under it (asi/library.py's on_ground). Given the ground's heights, a straight run
whose equal strides would put a sole across a bend or on ground steeper than GroundGait's
steep_rad (12 degrees) is planned on the ground instead (ground_strides.py: footholds clear
of the bends, short slow strides on the steep part); every other run keeps its equal
strides.
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
from tutorial_atlas_control.walking.ground_strides import (
    GroundGait,
    HeightField,
    ground_steps,
    sole_fit,
)

__all__ = ['RouteGait', 'centre_line_xy', 'feet_origin', 'route_steps']

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
    #: Whether a walker that knows the world's ground plans its straight runs on it
    #: (route_steps' `ground`: the pit's ramps). On: the pen-to-gate_1 legs plan the same
    #: steps either way, and the pit walks only so (docs/vrc.md).
    fit_ground: bool = True
    #: How far (m) the ground under a foothold (and its margins) may lie off one plane and
    #: still count as clear of a bend, on ground fitted so. The course's ground is a curved
    #: heightfield: over 3 m of the pit's exit ramp most places a sole could stand lie 5-14
    #: mm off a plane, and at ground_strides' 5 mm (its box ramps' sharp bends) the planner
    #: pulled footholds back and swung up to 0.33 m; at 1 cm the strides there are even
    #: (docs/vrc.md).
    ground_flat_m: float = 0.01
    #: Whether the turn towards the first waypoint is made on the spot whatever
    #: `turn_stride_m`: from rest, as a leg begins, there are no strides to stop from, and a
    #: walker beside an obstacle faces its way out without sweeping a circle.
    start_in_place: bool = False
    #: Whether a waypoint the turning strides cannot face (it lies inside their circle) is
    #: faced on the spot instead of refused.
    inside_in_place: bool = False
    #: The most (m) a stride shortens from one step to the next into a turn (0: at once,
    #: from full strides to the turning steps): the straight run before a corner ends in
    #: strides stepping down to the turning steps' length.
    turn_slowdown_m: float = 0.0

    def turning_in_place(self) -> RouteGait:
        """This gait with its turns in place: among obstacles, where a corner must be
        turned on the spot (a turning stride sweeps a circle)."""
        return replace(self, turn_stride_m=0.0)

    def __post_init__(self) -> None:
        numbers = (self.stride_m, self.turn_step_rad, self.width_m, self.duration_s,
                   self.ground_flat_m)
        if not all(math.isfinite(value) and value > 0.0 for value in numbers) \
                or not all(math.isfinite(value) and value >= 0.0
                           for value in (self.turn_stride_m, self.turn_slowdown_m)):
            raise WalkingError(f'a route gait needs positive finite numbers (a turning '
                               f'stride of 0 turns in place): {self}')


#: A move of the centre line: its heading (rad), length (m) and the step's duration (s).
Move = tuple[float, float, float]


def _turn(heading_rad: float, goal_rad: float, gait: RouteGait) -> list[Move]:
    """The moves turning from `heading_rad` to face `goal_rad` in equal parts of at most a
    step's turn."""
    turn = wrap_angle(goal_rad - heading_rad)
    count = math.ceil(abs(turn) / gait.turn_step_rad - 1e-9)
    return [(heading_rad + turn * (k + 1) / count, gait.turn_stride_m, gait.duration_s)
            for k in range(count)]


def _straight(start_xy: tuple[float, float], heading_rad: float, distance_m: float,
              gait: RouteGait, ground: HeightField | None, foot: int) -> list[Move]:
    """The moves straight over `distance_m`, `foot` first: equal strides of at most the
    gait's, or (`ground` given, and one of those footholds across a bend or steep) the
    run's strides fitted to the ground, without its last step (the feet side by side)."""
    count = math.ceil(distance_m / gait.stride_m - 1e-9)
    equal = [(heading_rad, distance_m / count, gait.duration_s)] * count
    if ground is None:
        return equal
    fitted = GroundGait(stride_m=gait.stride_m, duration_s=gait.duration_s,
                        width_m=gait.width_m, flat_m=gait.ground_flat_m)
    cos, sin = math.cos(heading_rad), math.sin(heading_rad)
    for k in range(1, count + 1):
        along = distance_m * k / count
        sole = _foot_at(k, foot if k % 2 == 1 else 1 - foot, start_xy[0] + along * cos,
                        start_xy[1] + along * sin, heading_rad, gait, gait.duration_s)
        fit = sole_fit(ground, sole.x_m, sole.y_m, heading_rad, fitted)
        if not fit.flat or fit.slope_rad > fitted.steep_rad:
            break
    else:
        return equal
    steps = ground_steps(distance_m, ground, fitted, start_xy, heading_rad, foot)[:-1]
    moves, last = [], 0.0
    for step in steps:
        along = (step.x_m - start_xy[0]) * cos + (step.y_m - start_xy[1]) * sin
        moves.append((heading_rad, along - last, step.duration_s))
        last = along
    return moves


def _slowed(run: list[Move], end_m: float, gait: RouteGait) -> list[Move]:
    """A straight run of equal strides ending in strides that step down by at most the
    gait's turn_slowdown_m to `end_m` (the turning step's length after it); the same run
    when it is not one of equal strides or is too short to step down."""
    if not run or len({move[1:] for move in run}) > 1:
        return run
    heading, stride, duration = run[0]
    slowing: list[float] = []
    while (length := end_m + gait.turn_slowdown_m * (len(slowing) + 1)) < stride - 1e-9:
        slowing.insert(0, length)
    rest = sum(move[1] for move in run) - sum(slowing)
    if not slowing or rest <= 0.0:
        return run
    count = math.ceil(rest / gait.stride_m - 1e-9)
    return [(heading, rest / count, duration)] * count \
        + [(heading, length, duration) for length in slowing]


def _facing(start_xy: tuple[float, float], heading_rad: float, goal: tuple[float, float],
            stride_m: float, gait: RouteGait) -> list[Move] | None:
    """The turning steps (each `stride_m` long) until `goal`'s bearing is within a step's
    turn (each moves the centre, so the bearing is taken again); None when no step faces it
    (it lies inside their turning circle)."""
    (x, y), heading = start_xy, heading_rad
    moves: list[Move] = []
    for _ in range(MAX_TURNING_STEPS):
        turn = wrap_angle(math.atan2(goal[1] - y, goal[0] - x) - heading)
        if math.hypot(goal[0] - x, goal[1] - y) < REACHED_M or abs(turn) <= gait.turn_step_rad:
            return moves
        heading += math.copysign(gait.turn_step_rad, turn)
        x += stride_m * math.cos(heading)
        y += stride_m * math.sin(heading)
        moves.append((heading, stride_m, gait.duration_s))
    return None


def _moves(start_xy: tuple[float, float], start_yaw_rad: float,
           waypoints: Sequence[tuple[float, float]], final_heading_rad: float | None,
           gait: RouteGait, ground: HeightField | None = None, first_foot: int = LEFT
           ) -> list[Move]:
    """The centre line's moves through every waypoint: turning steps to face it (_facing; on
    the spot as the gait says), then strides straight to it (_straight; step k moves
    `first_foot` for odd k)."""
    x, y = start_xy
    heading = start_yaw_rad
    moves: list[Move] = []
    run = 0  # where the last straight run's moves begin
    for number, goal in enumerate(waypoints):
        if not (math.isfinite(goal[0]) and math.isfinite(goal[1])):
            raise WalkingError(f'waypoint ({goal[0]}, {goal[1]}) is not finite')
        stride = 0.0 if number == 0 and gait.start_in_place else gait.turn_stride_m
        turns = _facing((x, y), heading, goal, stride, gait)
        if turns is None and stride > 0.0 and gait.inside_in_place:
            turns = _facing((x, y), heading, goal, 0.0, gait)
        if turns is None:
            raise WalkingError(f'waypoint ({goal[0]}, {goal[1]}) lies inside the turning circle '
                               f'from ({x:.3f}, {y:.3f}): no step faces it')
        for heading, length, _ in turns:
            x += length * math.cos(heading)
            y += length * math.sin(heading)
        if turns and gait.turn_slowdown_m > 0.0:
            moves[run:] = _slowed(moves[run:], turns[0][1], gait)
        moves += turns
        run = len(moves)
        goal_x, goal_y = goal
        distance = math.hypot(goal_x - x, goal_y - y)
        if distance < REACHED_M:
            continue
        heading = math.atan2(goal_y - y, goal_x - x)
        moves += _straight((x, y), heading, distance, gait, ground,
                           first_foot if len(moves) % 2 == 0 else 1 - first_foot)
        x, y = goal_x, goal_y
    if final_heading_rad is not None:
        moves += _turn(heading, final_heading_rad, gait)
    return moves


def route_steps(start_xy: tuple[float, float], start_yaw_rad: float,
                waypoints: Sequence[tuple[float, float]], gait: RouteGait | None = None,
                final_heading_rad: float | None = None, ground: HeightField | None = None
                ) -> list[Footstep]:
    """The steps (indices from 1) walking from feet side by side at `start_xy` facing
    `start_yaw_rad` through `waypoints` (world x, y), the last step bringing the feet side
    by side. The first foot to move is the one on the side of the first turn (left when
    the route starts straight). `ground`: the world's heights, for straight runs over a
    bend or steep ground (None: equal strides everywhere).

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
    if ground is not None:  # the same first move, its strides fitted to the ground
        moves = _moves(start_xy, start_yaw_rad, waypoints, final_heading_rad, gait, ground,
                       first_foot)
    steps = []
    x, y = start_xy
    heading = start_yaw_rad
    for k, (heading, length, duration) in enumerate(moves, start=1):
        x += length * math.cos(heading)
        y += length * math.sin(heading)
        steps.append(_foot_at(k, first_foot if k % 2 == 1 else 1 - first_foot, x, y, heading,
                              gait, duration))
    last = len(moves) + 1
    steps.append(_foot_at(last, first_foot if last % 2 == 1 else 1 - first_foot, x, y, heading,
                          gait, gait.duration_s))
    return steps


def _foot_at(index: int, foot: int, x_m: float, y_m: float, heading_rad: float,
             gait: RouteGait, duration_s: float) -> Footstep:
    """Step `index` of `foot`: half the width to its side of the centre line's point."""
    half = side_sign(foot) * gait.width_m / 2
    return Footstep(index, foot, x_m - half * math.sin(heading_rad),
                    y_m + half * math.cos(heading_rad), wrap_angle(heading_rad), duration_s)


def centre_line_xy(step: Footstep, width_m: float) -> tuple[float, float]:
    """The centre line's point `step` stands beside, `width_m` the stance (_foot_at's
    inverse)."""
    half = side_sign(step.foot_index) * width_m / 2
    return step.x_m + half * math.sin(step.yaw_rad), step.y_m - half * math.cos(step.yaw_rad)


def feet_origin(left: tuple[float, float, float],
                right: tuple[float, float, float]) -> tuple[tuple[float, float], float]:
    """Where a route starts from feet at `left` and `right` ((x, y, yaw), world): their
    midpoint and mean heading (the mean taken across the short way between the two yaws)."""
    heading = wrap_angle(left[2] + 0.5 * wrap_angle(right[2] - left[2]))
    return (0.5 * (left[0] + right[0]), 0.5 * (left[1] + right[1])), heading
