"""A course leg's steps (offline/course_route.leg_plan), as the offline and the live walker
plan them: on the course's description alone (course_height_m, the live walker's ground) the
pit's ramps get the short slow strides the offline walker's world gives them, the hills leg
keeps to its gentle way, and the rubble's corners are turned in strides, every sole clear of
the blocks (on the spot where turning strides would near one)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tutorial_atlas_control.course import (
    BLOCKS,
    COURSE_LEGS,
    RUBBLE_SEED,
    SOLE_CLEARANCE_M,
    Block,
    course_height_m,
    gentle_path,
    rearranged_blocks,
    sole_clearances_m,
)
from tutorial_atlas_control.offline import around_blocks, leg_plan
from tutorial_atlas_control.offline.course_route import CORNER_SLOWDOWN_M
from tutorial_atlas_control.walking import (
    LEFT,
    SOLE_HALF_LENGTH_M,
    SOLE_HALF_WIDTH_M,
    Footstep,
    GroundGait,
    RouteGait,
    route_steps,
)
from tutorial_atlas_control.walking.footsteps import STANCE_WIDTH_M

LEGS = {leg.gate: leg for leg in COURSE_LEGS}


def strides(steps: list) -> list[float]:
    return [math.hypot(b.x_m - a.x_m, b.y_m - a.y_m) for a, b in zip(steps, steps[2:])]


def test_the_pit_leg_on_the_course_description_takes_short_slow_strides_on_its_ramps() -> None:
    steep = GroundGait()
    fitted = leg_plan(LEGS['gate_2'], (0.5, -21.9), math.pi / 2, RouteGait(), BLOCKS,
                      course_height_m)
    equal = leg_plan(LEGS['gate_2'], (0.5, -21.9), math.pi / 2, RouteGait(fit_ground=False),
                     BLOCKS, course_height_m)
    slow = [step for step in fitted if step.duration_s == pytest.approx(steep.steep_duration_s)]
    assert len(slow) >= 20  # down the ramp into the pit and up out of it
    assert min(strides(fitted)) <= steep.steep_stride_m + 1e-9
    assert {step.duration_s for step in equal} == {RouteGait().duration_s}
    assert len(fitted) > len(equal) + 10
    for plan in (fitted, equal):
        last = plan[-1]
        assert math.hypot(last.x_m - 0.5, last.y_m + 10.0) < 0.2


def centre_of(step: Footstep) -> tuple[float, float, float]:
    """The centre line's point and heading a step was placed from (half the width aside)."""
    half = STANCE_WIDTH_M / 2 * (1.0 if step.foot_index == LEFT else -1.0)
    return (step.x_m + half * math.sin(step.yaw_rad), step.y_m - half * math.cos(step.yaw_rad),
            step.yaw_rad)


def spots_and_turning_strides(origin: tuple[float, float], heading: float,
                              plan: list[Footstep]) -> tuple[list[int], list[int], float]:
    """The moves turned on the spot and those turned in strides (their indices), and the
    largest turn between two steps (rad)."""
    centres = [(*origin, heading)] + [centre_of(step) for step in plan]
    moved = [math.dist(a[:2], b[:2]) for a, b in zip(centres, centres[1:])]
    turned = [abs(math.remainder(b[2] - a[2], math.tau)) for a, b in zip(centres, centres[1:])]
    spots = [k for k, (m, t) in enumerate(zip(moved, turned)) if m < 1e-9 and t > 0.05]
    strides = [k for k, (m, t) in enumerate(zip(moved, turned))
               if m == pytest.approx(RouteGait().turn_stride_m) and t > 0.05]
    return spots, strides, max(turned)


def sole_clearances(plan: list[Footstep], blocks: tuple[Block, ...]) -> np.ndarray:
    return sole_clearances_m([(step.x_m, step.y_m, step.yaw_rad) for step in plan], blocks,
                             (SOLE_HALF_LENGTH_M, SOLE_HALF_WIDTH_M))


def test_the_hills_leg_walks_its_gentle_way() -> None:
    hills = leg_plan(LEGS['gate_3'], (0.5, -10.0), math.pi / 2, RouteGait(), BLOCKS,
                     course_height_m)
    way = gentle_path((0.5, -10.0), LEGS['gate_3'].waypoints[-1])
    centre = [((a.x_m + b.x_m) / 2, (a.y_m + b.y_m) / 2) for a, b in zip(hills, hills[1:])]
    for corner in way:  # the walk passes every corner of its way
        assert min(math.dist(corner, point) for point in centre) < 0.3


@pytest.mark.parametrize('blocks', [BLOCKS, rearranged_blocks(BLOCKS, RUBBLE_SEED)],
                         ids=['shipped', 'finals'])
@pytest.mark.parametrize('origin', [(6.0, 6.6), (6.0, 7.0)], ids=['clear', 'beside a block'])
def test_the_rubble_s_corners_are_turned_in_strides_clear_of_the_blocks(
        blocks: tuple[Block, ...], origin: tuple[float, float]) -> None:
    plan = leg_plan(LEGS['gate_4'], origin, math.pi / 2, RouteGait(), blocks, course_height_m)
    spots, strides, widest_turn = spots_and_turning_strides(origin, math.pi / 2, plan)
    assert widest_turn <= RouteGait().turn_step_rad + 1e-9
    assert len(strides) >= 10  # its 5-7 corners
    # On the spot only as the leg begins (facing the way out from beside a block), never
    # after full strides: there the stance foot tipped onto its toe (docs/vrc.md).
    assert not spots or max(spots) < min(strides)
    assert max(spots, default=0) < 30
    # Every sole keeps clear of the blocks (the start beside one aside: out to its way first).
    # Into each corner the strides step down to the turning steps' length (the leg's end aside).
    centres = [centre_of(step)[:2] for step in plan[max(spots, default=0):]]
    moved = [math.dist(a, b) for a, b in zip(centres, centres[1:-1])]
    assert max(a - b for a, b in zip(moved, moved[1:])) <= CORNER_SLOWDOWN_M + 1e-9
    clear = sole_clearances(plan, blocks)[max(spots, default=-1) + 1:]
    assert clear.min() >= SOLE_CLEARANCE_M
    assert math.dist(centre_of(plan[-1])[:2], LEGS['gate_4'].waypoints[-1]) < 1e-6


def test_a_corner_whose_turning_strides_would_near_a_block_is_turned_on_the_spot() -> None:
    def flat(x: float, y: float) -> float:
        return 0.0

    way = [(20.0, 3.0), (23.0, 3.0)]  # north 3 m, then a right angle east
    plans = {}
    for north in (3.8, 4.2):  # a block lying east-west, this far north of the corner
        blocks = (Block('b', 20.3, north, 0.0, 0.0, 0.0, 0.0),)
        plan = around_blocks((20.0, 0.0), math.pi / 2, way, RouteGait(), blocks, flat, None)
        assert sole_clearances(plan, blocks).min() >= SOLE_CLEARANCE_M
        plans[north] = spots_and_turning_strides((20.0, 0.0), math.pi / 2, plan)
    # 0.75 m beyond the corner the turning strides would bring a sole within 0.2 m of it.
    near = (Block('b', 20.3, 3.8, 0.0, 0.0, 0.0, 0.0),)
    swept = route_steps((20.0, 0.0), math.pi / 2, way, RouteGait(), ground=flat)
    assert sole_clearances(swept, near).min() < SOLE_CLEARANCE_M
    spots, strides, _ = plans[3.8]
    assert len(spots) >= 7 and not strides
    spots, strides, _ = plans[4.2]  # 1.15 m beyond it, they keep clear
    assert len(strides) >= 7 and not spots
