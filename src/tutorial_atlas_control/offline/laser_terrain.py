"""A course walker's ground from its head laser, offline: the spindle spinning, the scans of
the simulated course cast as the live node casts them, a height map of them
(sensors/height_map.py) updated as the robot stands and walks, and the ground a leg is
planned on read from that map instead of the world.

Where the map does not know the ground (not seen yet, or behind a lump), the planner takes
the nearest known cell's height: unseen ground continues the nearest seen ground. Stopping
there would stop every leg, whose plan asks for the ground up to its last waypoint metres
away, and the world's heights would defeat the map; the walker already stands spinning the
laser before each leg (3 s before the first, LEG_PAUSE_S between), and each fallback is
counted and its distance kept (LaserLegFigures), so a plan leaning on unseen ground shows.
How close the map is: at every footstep a leg chose, its height against the course's
description (course_height_m), beside the plan the world's ground would have given.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from tutorial_atlas_control import topics
from tutorial_atlas_control.course import course_height_m
from tutorial_atlas_control.sensors import HeightMap, HeightMapSpec, HokuyoLaser, Spindle
from tutorial_atlas_control.sim import AtlasSimulator
from tutorial_atlas_control.stepping import steps_between
from tutorial_atlas_control.walking import Footstep, GroundGait, sole_fit

__all__ = ['LOOK_AGAIN_AFTER_STEPS', 'LOOK_AGAIN_SLOPE_RAD', 'SPIN_RAD_S', 'LaserLegFigures',
           'LaserTerrain', 'PlanningGround', 'footstep_errors', 'level_footstep',
           'seen_prefix', 'unlike_plan']

#: The spindle's speed (rad/s): half a turn (every direction once) in 3.1 s, the scans
#: 25 mrad apart, 7.5 cm at 3 m.
SPIN_RAD_S = 1.0
#: A fallback farther than this (m) from the nearest known cell is warned about.
FAR_FALLBACK_M = 0.5
#: A leg planned on the map is walked at least this many steps before it may stop to look
#: again: the map never sees the ground under and beside the robot (its self filter).
LOOK_AGAIN_AFTER_STEPS = 8
#: It stops to look again only where both feet stand on ground this level (rad) or less,
#: one plane within 1 cm under each sole (the course's curved ground: walking/route.py).
LOOK_AGAIN_SLOPE_RAD = math.radians(6.0)
_STANDING_FIT = GroundGait(flat_m=0.01)


class PlanningGround:
    """The map's ground for a planner: its height where known, else the nearest known
    cell's, each such fallback counted with its distance."""

    def __init__(self, height_map: HeightMap) -> None:
        self.map = height_map
        self.asked = 0
        self.fallbacks = 0
        self.farthest_m = 0.0

    def __call__(self, x_m: float, y_m: float) -> float:
        self.asked += 1
        height = self.map.height_m(x_m, y_m)
        if math.isfinite(height):
            return height
        height, distance = self.map.nearest_m(x_m, y_m)
        if not math.isfinite(height):
            raise ValueError('the laser has seen no ground yet')
        self.fallbacks += 1
        self.farthest_m = max(self.farthest_m, distance)
        return height


@dataclass(frozen=True)
class LaserLegFigures:
    """One leg planned on the laser's map: its steps and the world's plan's, how many of its
    footsteps stood on known ground, the map's error there against course_height_m (m;
    p50, p95, max of the absolute error, and the signed median), the planner's fallbacks
    (asked, fallen back, the farthest, m), the map's points then, and how many of its steps
    are not the world's plan's (index by index: another foot, 1 cm away or another
    duration; the steps one plan has beyond the other count too)."""

    gate: str
    steps: int
    steps_world: int
    footsteps_known: int
    error_p50_m: float
    error_p95_m: float
    error_max_m: float
    error_median_m: float
    asked: int
    fallbacks: int
    farthest_fallback_m: float
    points: int
    steps_unlike_world: int = 0


def seen_prefix(plan: Sequence[Footstep], height_map: HeightMap,
                level: Callable[[Footstep], bool] | None = None) -> int:
    """How many of `plan`'s steps to walk before stopping to look again and plan the rest:
    all when every footstep from the LOOK_AGAIN_AFTER_STEPS'th on stands on ground the map
    has seen; else up to the last step before the first that does not, going back to where
    the last two footsteps are both `level` (None: anywhere), never fewer than
    LOOK_AGAIN_AFTER_STEPS (then, with no level place, up to the unseen step anyway). The
    map's fallback (the nearest seen cell's height) is fine near what it saw and off by
    decimetres metres away: live, the hills leg planned at gate_2 had 65 of 183 footsteps
    on unseen ground, up to 6.7 m from it, 25 cm off, and fell after 86 steps."""
    unseen = next((k for k in range(LOOK_AGAIN_AFTER_STEPS, len(plan))
                   if not math.isfinite(height_map.height_m(plan[k].x_m, plan[k].y_m))), None)
    if unseen is None:
        return len(plan)
    if level is None:
        return unseen
    stop = next((k for k in range(unseen, LOOK_AGAIN_AFTER_STEPS, -1)
                 if level(plan[k - 1]) and level(plan[k - 2])), None)
    return unseen if stop is None else stop


def level_footstep(ground: Callable[[float, float], float]) -> Callable[[Footstep], bool]:
    """Whether a footstep's sole stands on one plane of `ground` within
    LOOK_AGAIN_SLOPE_RAD of level (walking/ground_strides.sole_fit)."""
    def level(step: Footstep) -> bool:
        fit = sole_fit(ground, step.x_m, step.y_m, step.yaw_rad, _STANDING_FIT)
        return fit.flat and fit.slope_rad <= LOOK_AGAIN_SLOPE_RAD
    return level


def footstep_errors(steps: Sequence[Footstep], ground: PlanningGround
                    ) -> tuple[int, np.ndarray]:
    """(how many footsteps the map knew, each footstep's map height minus the course's)."""
    known = sum(math.isfinite(ground.map.height_m(s.x_m, s.y_m)) for s in steps)
    errors = np.array([ground(s.x_m, s.y_m) - course_height_m(s.x_m, s.y_m) for s in steps])
    return known, errors


class LaserTerrain:
    """The head's laser on a course simulator: the spindle stepped with each physics step,
    a scan every 25 ms added to the height map with the pelvis's (x, y) for its self filter.

    Args:
        seed: the laser noise's seed.
        spin_rad_s: the spindle's speed (rad/s).
    """

    def __init__(self, sim: AtlasSimulator, seed: int = 0, spin_rad_s: float = SPIN_RAD_S,
                 spec: HeightMapSpec | None = None) -> None:
        self.sim = sim
        self.laser = HokuyoLaser(sim.model, seed=seed)
        self.spindle = Spindle(sim.dt_s)
        self.spindle.command(spin_rad_s)
        self.map = HeightMap(spec)
        self.every = steps_between(topics.BY_NAME[topics.LASER_SCAN].rate.default_hz,
                                   sim.dt_s)
        self._ranges = np.zeros(self.laser.spec.samples, dtype=np.float32)
        self._angles = self.laser.spec.angles()
        self.ticks = 0

    def after_step(self) -> None:
        """With each physics step: the spindle's step; a scan when one is due (the step's
        start: the poses mj_step computed and the spindle's angle before its step)."""
        self.spindle.step()
        self.ticks += 1
        if self.ticks % self.every:
            return
        data, angle = self.sim.data, self.spindle.previous_angle
        self.laser.scan(data, angle, self.sim.state_time_ns, self._ranges)
        origin, rotation = self.laser.frame_pose(data, angle)
        pelvis = data.xpos[self.sim.atlas.pelvis_body_id]
        self.map.add_scan(origin, rotation, self._angles, self._ranges,
                          (float(pelvis[0]), float(pelvis[1])))

    def leg_figures(self, gate: str, plan: Sequence[Footstep], world_plan: Sequence[Footstep],
                    ground: PlanningGround) -> LaserLegFigures:
        """The figures of a leg planned on `ground` (this map's) as `plan`."""
        asked, fallbacks, farthest = ground.asked, ground.fallbacks, ground.farthest_m
        known, errors = footstep_errors(plan, ground)
        size = np.abs(errors) if len(errors) else np.zeros(1)
        return LaserLegFigures(
            gate, len(plan), len(world_plan), known,
            round(float(np.percentile(size, 50)), 4), round(float(np.percentile(size, 95)), 4),
            round(float(size.max()), 4), round(float(np.median(errors)) if len(errors) else 0.0, 4),
            asked, fallbacks, round(farthest, 3), len(self.map.points),
            unlike_plan(plan, world_plan))


def unlike_plan(plan: Sequence[Footstep], other: Sequence[Footstep]) -> int:
    """How many of `plan`'s steps are not `other`'s, index by index (another foot, 1 cm
    away or another duration), and the steps one has beyond the other."""
    unlike = abs(len(plan) - len(other))
    for ours, theirs in zip(plan, other):
        unlike += (ours.foot_index != theirs.foot_index
                   or math.hypot(ours.x_m - theirs.x_m, ours.y_m - theirs.y_m) > 0.01
                   or abs(ours.duration_s - theirs.duration_s) > 1e-6)
    return unlike
