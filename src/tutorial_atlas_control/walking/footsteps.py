"""Footsteps as the AtlasSimInterface takes them, and the plans the tests and demos walk.

A step (`atlas_msgs/AtlasBehaviorStepData`) names its foot (0 left, 1 right), its index in the
walk (1 is the first step; 0 stands for where the feet were when Walk began), how long it
takes and where the sole lands: x, y and yaw in the frame of `pos_est`, which starts where
the robot starts. Here a step is the sole's whole pose: its centre's height too (the surface it
lands on, 0 on the ground the robot starts on) and the surface's normal where known; swings end
on it. The plans here are DRCSim's fixed `control_mode Walk` queue, a straight line and a
circle, on flat ground.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from tutorial_atlas_control.msgs import STEP_QUEUE_LENGTH
from tutorial_atlas_control.walking.errors import WalkingError

LEFT, RIGHT = 0, 1
#: How many steps a WALK command carries (`walk_params.step_queue`).
QUEUE_LENGTH = STEP_QUEUE_LENGTH
#: DRCSim's step duration (s) and distance between the feet's centres (m).
STEP_DURATION_S = 0.63
STANCE_WIDTH_M = 0.24


@dataclass(frozen=True)
class Footstep:
    """Where and when one foot lands: the sole's centre (m) and heading (rad), world frame;
    `z_m` the height of the sole's bottom face there (the surface it lands on), `normal` that
    surface's unit normal (upright unless known)."""

    step_index: int
    foot_index: int
    x_m: float
    y_m: float
    yaw_rad: float
    duration_s: float = STEP_DURATION_S
    z_m: float = 0.0
    normal: tuple[float, float, float] = (0.0, 0.0, 1.0)

    def __post_init__(self) -> None:
        if self.foot_index not in (LEFT, RIGHT):
            raise WalkingError(f'step {self.step_index}: foot_index {self.foot_index} is not '
                             '0 (left) or 1 (right)')
        values = (self.x_m, self.y_m, self.z_m, self.yaw_rad, self.duration_s, *self.normal)
        if not all(math.isfinite(value) for value in values):
            raise WalkingError(f'step {self.step_index}: a pose or duration is not finite')
        if len(self.normal) != 3 or abs(math.hypot(*self.normal) - 1.0) > 1e-6 \
                or self.normal[2] <= 0.0:
            raise WalkingError(f'step {self.step_index}: surface normal {self.normal} is not '
                             'a unit vector pointing up')
        if self.duration_s <= 0.0:
            raise WalkingError(f'step {self.step_index}: duration {self.duration_s} s is not '
                             'positive')


#: `/atlas/control_mode Walk`'s fixed queue (DRCSim's AtlasPlugin): L, R, L, R, 0.2 m apart.
DRCSIM_WALK_QUEUE: tuple[Footstep, ...] = (
    Footstep(1, LEFT, 0.2, 0.12, 0.0),
    Footstep(2, RIGHT, 0.4, -0.12, 0.0),
    Footstep(3, LEFT, 0.6, 0.12, 0.0),
    Footstep(4, RIGHT, 0.8, -0.12, 0.0),
)


def side_sign(foot_index: int) -> float:
    """+1 for the left foot (it lies on the walker's left, +y), -1 for the right."""
    return 1.0 if foot_index == LEFT else -1.0


def straight_steps(count: int, stride_m: float, width_m: float = STANCE_WIDTH_M,
                   duration_s: float = STEP_DURATION_S, first_foot: int = LEFT) -> list[Footstep]:
    """`count` steps along +x from feet side by side at the origin, each foot `stride_m`
    ahead of the other one's last step; the last step brings the feet side by side."""
    if count < 1:
        raise WalkingError(f'a walk needs at least one step, not {count}')
    steps = []
    for k in range(1, count + 1):
        foot = first_foot if k % 2 == 1 else 1 - first_foot
        x = stride_m * (k if k < count else k - 1)
        steps.append(Footstep(k, foot, x, side_sign(foot) * width_m / 2, 0.0, duration_s))
    return steps


def circle_steps(radius_m: float, steps_per_circle: int, circles: int = 1,
                 width_m: float = STANCE_WIDTH_M, duration_s: float = STEP_DURATION_S,
                 first_foot: int = LEFT) -> list[Footstep]:
    """Walk counter-clockwise round a circle of `radius_m` whose centre is on the walker's
    left, starting at the origin facing +x: each step turns the heading by a
    1/`steps_per_circle` turn, the feet `width_m` apart across the path."""
    if radius_m <= width_m / 2:
        raise WalkingError(f'radius {radius_m} m: the inner foot would cross the centre')
    if steps_per_circle < 4 or circles < 1:
        raise WalkingError('a circle needs 4 or more steps, and one circle or more')
    steps = []
    for k in range(1, steps_per_circle * circles + 1):
        foot = first_foot if k % 2 == 1 else 1 - first_foot
        heading = 2.0 * math.pi * k / steps_per_circle
        # The path's point at this heading, then the foot across it (left: towards the centre).
        foot_radius = radius_m - side_sign(foot) * width_m / 2
        x = foot_radius * math.sin(heading)
        y = radius_m - foot_radius * math.cos(heading)
        steps.append(Footstep(k, foot, x, y, wrap_angle(heading), duration_s))
    return steps


def placed(plan: list[Footstep], origin_xy: tuple[float, float],
           yaw_rad: float) -> list[Footstep]:
    """`plan` (made from the origin facing +x) for a walker at `origin_xy` facing `yaw_rad`."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    x0, y0 = origin_xy
    return [replace(step, x_m=x0 + c * step.x_m - s * step.y_m,
                    y_m=y0 + s * step.x_m + c * step.y_m,
                    yaw_rad=wrap_angle(step.yaw_rad + yaw_rad)) for step in plan]


def wrap_angle(angle_rad: float) -> float:
    """The angle in [-pi, pi)."""
    return (angle_rad + math.pi) % (2.0 * math.pi) - math.pi


def window(plan: list[Footstep], first_index: int) -> list[Footstep]:
    """The QUEUE_LENGTH steps from `first_index` on (fewer at the plan's end): what a streaming
    client sends for `next_step_index_needed`."""
    by_index = {step.step_index: step for step in plan}
    return [by_index[k] for k in range(first_index, first_index + QUEUE_LENGTH)
            if k in by_index]
