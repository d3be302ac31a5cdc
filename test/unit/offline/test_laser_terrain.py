"""Course legs planned on the head laser's height map (offline/laser_terrain.py), from what it
sees standing at a start with the spindle turned half a turn (the model at its start pose):
the pen's leg is the world's plan, the pit's leg keeps the short slow strides on its ramps,
the map within centimetres of the course's description at the chosen footsteps."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.course import (
    BLOCKS,
    COURSE_LEGS,
    block_footprint,
    course_height_m,
    distance_to_polygon,
)
from tutorial_atlas_control.offline import (
    PlanningGround,
    footstep_errors,
    leg_plan,
    unlike_plan,
)
from tutorial_atlas_control.offline.course_route import _course_simulator
from tutorial_atlas_control.sensors import HeightMap, HokuyoLaser
from tutorial_atlas_control.walking import GroundGait, RouteGait

LEGS = {leg.gate: leg for leg in COURSE_LEGS}


def _seen_from_start(world: str) -> tuple[HeightMap, tuple[float, float], float]:
    """The map of half a spindle turn at 1 rad/s (126 scans) from `world`'s start, the
    pelvis's (x, y) and heading."""
    sim = _course_simulator(world, None)
    mujoco.mj_forward(sim.model, sim.data)
    laser = HokuyoLaser(sim.model, seed=1)
    pelvis = sim.data.xpos[sim.atlas.pelvis_body_id]
    xy = (float(pelvis[0]), float(pelvis[1]))
    height_map = HeightMap()
    ranges = np.zeros(laser.spec.samples, dtype=np.float32)
    for k in range(126):
        angle = k / laser.spec.rate_hz
        laser.scan(sim.data, angle, k, ranges)
        origin, rotation = laser.frame_pose(sim.data, angle)
        height_map.add_scan(origin, rotation, laser.spec.angles(), ranges, xy)
    heading = math.atan2(sim.data.xmat[sim.atlas.pelvis_body_id][3],
                         sim.data.xmat[sim.atlas.pelvis_body_id][0])
    return height_map, xy, heading


def test_the_pen_leg_planned_on_the_laser_map_is_the_worlds_plan() -> None:
    height_map, origin, heading = _seen_from_start('vrc_task_2')
    ground = PlanningGround(height_map)
    laser = leg_plan(LEGS['gate_0'], origin, heading, RouteGait(), BLOCKS, ground)
    world = leg_plan(LEGS['gate_0'], origin, heading, RouteGait(), BLOCKS, course_height_m)
    assert unlike_plan(laser, world) == 0
    assert unlike_plan(laser, world[:-2]) == 2
    known, errors = footstep_errors(laser, ground)
    assert known >= 0.7 * len(laser)
    assert np.abs(errors).max() < 0.01


def test_the_pit_leg_planned_on_the_laser_map_takes_slow_strides_on_its_ramps() -> None:
    height_map, origin, heading = _seen_from_start('vrc_task_2_mud_start')
    ground = PlanningGround(height_map)
    laser = leg_plan(LEGS['gate_2'], origin, heading, RouteGait(), BLOCKS, ground)
    world = leg_plan(LEGS['gate_2'], origin, heading, RouteGait(), BLOCKS, course_height_m)
    slow = GroundGait().steep_duration_s

    def slow_steps(plan: list) -> int:
        return sum(step.duration_s == pytest.approx(slow) for step in plan)

    assert slow_steps(world) >= 30
    assert abs(slow_steps(laser) - slow_steps(world)) <= 3
    known, errors = footstep_errors(laser, ground)
    assert known >= 0.75 * len(laser)
    assert np.median(np.abs(errors)) < 0.01
    assert np.percentile(np.abs(errors), 95) < 0.05


def test_the_rubble_leg_planned_around_the_laser_maps_obstacles_keeps_off_the_blocks() -> None:
    """From the rubble's start the map takes the blocks for obstacles (not the gates' bars
    overhead, which closed the way), and the way planned around them alone, without the
    world's blocks, keeps every footstep off every block as the world's plan does."""
    height_map, origin, heading = _seen_from_start('vrc_task_2_rubble_start')
    grid = height_map.grid
    seen = 0
    for block in BLOCKS:
        row, col = (int(round(float(v))) for v in grid.index(block.x_m, block.y_m))
        seen += bool(grid.obstacle[row - 1:row + 2, col - 1:col + 2].any())
    assert seen >= 28
    plan = leg_plan(LEGS['gate_4'], origin, heading, RouteGait(), (),
                    PlanningGround(height_map), grid.obstacle_xy())
    xs, ys = np.array([s.x_m for s in plan]), np.array([s.y_m for s in plan])
    nearest = min(float(distance_to_polygon(block_footprint(b), xs, ys).min()) for b in BLOCKS)
    assert nearest > 0.3
    assert math.hypot(plan[-1].x_m - 6.0, plan[-1].y_m - 18.5) < 0.2


def test_planning_ground_falls_back_on_the_nearest_seen_ground_and_counts_it() -> None:
    height_map = HeightMap()
    with pytest.raises(ValueError, match='no ground'):
        PlanningGround(height_map)(0.0, 0.0)
    xs, ys = np.meshgrid(np.arange(0.0, 1.0, 0.02), np.arange(0.0, 1.0, 0.02))
    height_map.add_points(np.stack((xs.ravel(), ys.ravel(), np.full(xs.size, 0.3)), 1))
    ground = PlanningGround(height_map)
    assert ground(0.5, 0.5) == pytest.approx(0.3)
    assert ground.fallbacks == 0
    assert ground(3.0, 0.5) == pytest.approx(0.3)
    assert ground.fallbacks == 1 and 1.7 < ground.farthest_m < 2.1
