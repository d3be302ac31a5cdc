"""Strides fitted to the ground along a straight run: no sole across a bend, short slow steps
on steep ground. What a footstep planner does before the interface puts the steps on the
ground under them (asi/library.py's on_ground: the surface under the sole's centre).

Up and down the VRC mud pit's 22-degree ramps (0.6 m over 1.5 m) Walk fell in 0.2 m strides
of 0.63 s (docs/vrc.md). Two things felled it:

- a sole across a bend (the ramp's foot, its top edge) is laid on the surface under its
  centre and tips over the bend. A sole is 0.26 m long: at any stride under about 0.3 m
  some foothold lands across a bend. Here a foothold across one is pulled back to the last
  place clear of it (where the other foot stands, at the least: beside it), and the bend is
  crossed in one longer stride (at most `crossing_m`) to the first clear place beyond it;
  the other foot then comes beside it (its swing is at most two steep strides) before
  striding on. (The highest ground under the footprint, as Step takes it, fell at the top
  edge: a sole flat on the platform, its heel over the ramp, rests on the edge.)
- on ground steeper than `steep_rad` (12 degrees) the steps are `steep_stride_m` long and
  take `steep_duration_s`: up 22 degrees in 0.2 m strides the ankles reached their
  dorsiflexion stop (0.698 rad: 0.384 of slope plus the shank's lean) and the pelvis
  pitched back; in 0.1 m strides of 0.9 s a constant 22-degree slope walked up for every
  start tried, and down (where 0.2 m strides left the pelvis under the trial's 0.8 m over
  the lower sole) too. Up the course's pit exit ramp in mud (17-22 degrees under a sole)
  0.15 m strides of 0.63 s fell where the threshold was 20 degrees; from 12 it walked.

A foothold is clear of bends when the ground under its sole and `margin_m` beyond its ends
lies within `flat_m` of the plane through the ground under its centre (the slopes along and
across it taken from its ends and sides). Heights only: the world's ground (sim/ground.py's
Ground.height_m) or any function of (x, y).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from tutorial_atlas_control.walking.errors import WalkingError
from tutorial_atlas_control.walking.footsteps import (
    LEFT,
    STANCE_WIDTH_M,
    STEP_DURATION_S,
    Footstep,
    side_sign,
    wrap_angle,
)

__all__ = ['SOLE_HALF_LENGTH_M', 'SOLE_HALF_WIDTH_M', 'GroundGait', 'HeightField', 'SoleFit',
           'ground_steps', 'sole_fit']

#: The ground's height (m) under a world (x, y).
HeightField = Callable[[float, float], float]

#: Atlas's sole box (sim/atlas_v1.xml): half its length and half its width (m).
SOLE_HALF_LENGTH_M = 0.13
SOLE_HALF_WIDTH_M = 0.0624
#: Places searched for a foothold clear of a bend, this far apart (m).
SEARCH_STEP_M = 0.01


@dataclass(frozen=True)
class GroundGait:
    """How a straight run is walked on uneven ground (ours; measured in docs/vrc.md)."""

    stride_m: float = 0.2
    duration_s: float = STEP_DURATION_S
    #: Ground steeper than this (rad) under a step's ends is walked in steep strides. At 20
    #: degrees the course's pit exit ramp (in mud) fell: its steps there flipped between
    #: normal strides on 17-20 degrees and steep ones.
    steep_rad: float = math.radians(12.0)
    steep_stride_m: float = 0.1
    steep_duration_s: float = 0.9
    #: The longest stride (and swing) that crosses a bend (m).
    crossing_m: float = 0.35
    #: The ground beyond the sole's ends that must be clear of a bend too (m), and how far
    #: (m) the ground under it may lie off its plane. Up the pit's ramp a margin of 2 cm put
    #: both soles' ends on the top edge (heel and toe within 1.5 cm of it) and the walk fell
    #: there, every seed; 3 to 5 cm walked.
    margin_m: float = 0.04
    flat_m: float = 0.005
    width_m: float = STANCE_WIDTH_M

    def __post_init__(self) -> None:
        numbers = (self.stride_m, self.duration_s, self.steep_rad, self.steep_stride_m,
                   self.steep_duration_s, self.crossing_m, self.flat_m, self.width_m)
        if not all(math.isfinite(value) and value > 0.0 for value in numbers) \
                or not (math.isfinite(self.margin_m) and self.margin_m >= 0.0):
            raise WalkingError(f'a ground gait needs positive finite numbers: {self}')


@dataclass(frozen=True)
class SoleFit:
    """The ground under a sole: whether it is one plane (no bend under the sole), and that
    plane's steepness (rad)."""

    flat: bool
    slope_rad: float


def sole_fit(height_m: HeightField, x_m: float, y_m: float, yaw_rad: float,
             gait: GroundGait | None = None) -> SoleFit:
    """The ground under a sole centred at (`x_m`, `y_m`) heading `yaw_rad`: sampled every
    2 cm along it (from `margin_m` behind its heel to as far past its toe) on its centre
    line and both edges, against the plane through its centre's height with the slopes
    between its ends and between its edges."""
    gait = gait or GroundGait()
    along = SOLE_HALF_LENGTH_M + gait.margin_m
    cos, sin = math.cos(yaw_rad), math.sin(yaw_rad)

    def ground(u: float, v: float) -> float:
        return height_m(x_m + u * cos - v * sin, y_m + u * sin + v * cos)

    centre = ground(0.0, 0.0)
    grade_u = (ground(along, 0.0) - ground(-along, 0.0)) / (2.0 * along)
    grade_v = (ground(0.0, SOLE_HALF_WIDTH_M) - ground(0.0, -SOLE_HALF_WIDTH_M)) \
        / (2.0 * SOLE_HALF_WIDTH_M)
    count = max(2, math.ceil(2.0 * along / 0.02))
    worst = 0.0
    for k in range(count + 1):
        u = -along + 2.0 * along * k / count
        for v in (-SOLE_HALF_WIDTH_M, 0.0, SOLE_HALF_WIDTH_M):
            worst = max(worst, abs(ground(u, v) - centre - grade_u * u - grade_v * v))
    return SoleFit(worst <= gait.flat_m, math.atan(math.hypot(grade_u, grade_v)))


def ground_steps(length_m: float, height_m: HeightField, gait: GroundGait | None = None,
                 start_xy: tuple[float, float] = (0.0, 0.0), heading_rad: float = 0.0,
                 first_foot: int = LEFT) -> list[Footstep]:
    """The steps (indices from 1) walking `length_m` straight along `heading_rad` from feet
    side by side at `start_xy` on the ground `height_m`, each foot in turn, the last step
    bringing the feet side by side: strides of the gait's length, or its steep ones where the
    ground under a step's ends is steep, each foothold clear of the ground's bends where a
    clear one is within reach (else as the stride puts it). Heights and normals are left to
    on_ground."""
    gait = gait or GroundGait()
    if not (math.isfinite(length_m) and length_m > 0.0):
        raise WalkingError(f'a straight run needs a positive length, not {length_m}')
    cos, sin = math.cos(heading_rad), math.sin(heading_rad)

    def sole_at(foot: int, along_m: float) -> tuple[float, float]:
        half = side_sign(foot) * gait.width_m / 2
        return start_xy[0] + along_m * cos - half * sin, start_xy[1] + along_m * sin + half * cos

    def fit(foot: int, along_m: float) -> SoleFit:
        return sole_fit(height_m, *sole_at(foot, along_m), heading_rad, gait)

    feet = [0.0, 0.0]
    foot = first_foot
    positions: list[tuple[int, float, bool]] = []
    while min(feet) < length_m - 1e-9 and len(positions) < 10 * length_m / gait.steep_stride_m:
        target = _next_foothold(feet, foot, length_m, fit, gait)
        steep = max(fit(foot, feet[foot]).slope_rad, fit(foot, target).slope_rad) \
            > gait.steep_rad
        positions.append((foot, target, steep))
        feet[foot] = target
        foot = 1 - foot
    steps = []
    for index, (moved, along, steep) in enumerate(positions, start=1):
        x_m, y_m = sole_at(moved, along)
        steps.append(Footstep(index, moved, x_m, y_m, wrap_angle(heading_rad),
                              gait.steep_duration_s if steep else gait.duration_s))
    return steps


def _next_foothold(feet: list[float], foot: int, length_m: float,
                   fit: Callable[[int, float], SoleFit], gait: GroundGait) -> float:
    """Where (m along the run) `foot` lands next: a stride ahead of the other foot (a steep
    one where either foot stands, or it would land, on steep ground; a swing of at most two
    strides; the run's end at most), pulled back to the last place clear of a bend (not
    behind where the foot is), or else over the bend to the first clear place within the
    crossing; as the stride puts it if none is."""
    other = feet[1 - foot]
    steep = max(fit(foot, place).slope_rad
                for place in (feet[foot], other, other + gait.stride_m)) > gait.steep_rad
    stride = gait.steep_stride_m if steep else gait.stride_m
    target = min(other + stride, length_m, max(other, feet[foot] + 2.0 * stride))
    if fit(foot, target).flat:
        return target
    back = target - SEARCH_STEP_M
    while back > feet[foot] + 1e-9 and back >= other - 1e-9:
        if fit(foot, back).flat:
            return back
        back -= SEARCH_STEP_M
    if other > feet[foot] + 1e-9 and fit(foot, other).flat:
        return other
    ahead = target + SEARCH_STEP_M
    while ahead <= min(feet[foot] + gait.crossing_m, length_m) + 1e-9:
        if fit(foot, ahead).flat:
            return ahead
        ahead += SEARCH_STEP_M
    return target
