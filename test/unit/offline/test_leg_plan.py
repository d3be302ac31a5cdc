"""A course leg's steps (offline/course_route.leg_plan), as the offline and the live walker
plan them: on the course's description alone (course_height_m, the live walker's ground) the
pit's ramps get the short slow strides the offline walker's world gives them, the hills leg
keeps to its gentle way, and the rubble's corners are turned on the spot."""

from __future__ import annotations

import math

import pytest

from tutorial_atlas_control.course import (
    BLOCKS,
    COURSE_LEGS,
    course_height_m,
    gentle_path,
)
from tutorial_atlas_control.offline import leg_plan
from tutorial_atlas_control.walking import GroundGait, RouteGait

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


def test_the_hills_leg_walks_its_gentle_way_and_the_rubble_turns_on_the_spot() -> None:
    hills = leg_plan(LEGS['gate_3'], (0.5, -10.0), math.pi / 2, RouteGait(), BLOCKS,
                     course_height_m)
    way = gentle_path((0.5, -10.0), LEGS['gate_3'].waypoints[-1])
    centre = [((a.x_m + b.x_m) / 2, (a.y_m + b.y_m) / 2) for a, b in zip(hills, hills[1:])]
    for corner in way:  # the walk passes every corner of its way
        assert min(math.dist(corner, point) for point in centre) < 0.3
    rubble = leg_plan(LEGS['gate_4'], (6.0, 7.0), math.pi / 2, RouteGait(), BLOCKS,
                      course_height_m)
    centres = [((a.x_m + b.x_m) / 2, (a.y_m + b.y_m) / 2, b.yaw_rad)
               for a, b in zip(rubble, rubble[1:])]
    turned_on_the_spot = [k for k, (a, b) in enumerate(zip(centres, centres[1:]))
                          if math.dist(a[:2], b[:2]) < 0.04 and abs(b[2] - a[2]) > 0.05]
    assert len(turned_on_the_spot) >= 3
