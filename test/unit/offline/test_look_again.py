"""A leg planned on the laser's map is walked only as far as the map has seen, stopping
where both feet stand level, then planned again (offline.seen_prefix, level_footstep)."""

from __future__ import annotations

import math

from tutorial_atlas_control.course import COURSE_LEGS, rest_of_leg
from tutorial_atlas_control.offline import (
    LOOK_AGAIN_AFTER_STEPS,
    level_footstep,
    resumed_leg,
    seen_prefix,
)
from tutorial_atlas_control.walking import Footstep, RouteGait, straight_steps

PLAN = straight_steps(20, 0.15)  # x 0.15 k, alternate feet


class _SeenUpTo:
    """A map that has seen the ground up to `x_m` (and none within `blind_m` of x 0.1)."""

    def __init__(self, x_m: float, blind_m: float = 0.0) -> None:
        self.x_m, self.blind_m = x_m, blind_m

    def height_m(self, x_m: float, _y_m: float) -> float:
        return 0.0 if x_m <= self.x_m and abs(x_m - 0.1) >= self.blind_m else math.nan


def test_a_plan_the_map_has_seen_is_walked_whole() -> None:
    assert seen_prefix(PLAN, _SeenUpTo(10.0)) == len(PLAN)


def test_the_walk_stops_before_the_first_unseen_footstep() -> None:
    first_unseen = next(k for k, step in enumerate(PLAN) if step.x_m > 1.9)
    assert first_unseen > LOOK_AGAIN_AFTER_STEPS
    assert seen_prefix(PLAN, _SeenUpTo(1.9)) == first_unseen


def test_the_ground_under_the_robot_unseen_does_not_stop_it() -> None:
    """The map never sees the robot's own surroundings: the first steps may be unseen."""
    assert not math.isfinite(_SeenUpTo(10.0, blind_m=0.3).height_m(PLAN[0].x_m, 0.0))
    assert seen_prefix(PLAN, _SeenUpTo(10.0, blind_m=0.3)) == len(PLAN)
    assert seen_prefix(PLAN, _SeenUpTo(0.5)) == LOOK_AGAIN_AFTER_STEPS  # not before


def test_it_goes_back_to_where_both_feet_stand_level() -> None:
    first_unseen = next(k for k, step in enumerate(PLAN) if step.x_m > 1.9)
    sloped = {first_unseen - 1, first_unseen - 2}  # the last two seen footsteps

    def level(step: Footstep) -> bool:
        return step.step_index - 1 not in sloped

    assert seen_prefix(PLAN, _SeenUpTo(1.9), level) == first_unseen - 2
    assert seen_prefix(PLAN, _SeenUpTo(1.9), lambda _step: False) == first_unseen


def test_level_is_a_plane_within_six_degrees() -> None:
    step = PLAN[3]
    for degrees, expected in ((0.0, True), (5.0, True), (8.0, False)):
        slope = math.tan(math.radians(degrees))
        assert level_footstep(lambda x, _y, s=slope: s * x)(step) is expected, degrees
    crease = level_footstep(lambda x, _y: 0.2 * max(0.0, x - step.x_m))  # bent, 5.7 deg
    assert crease(step) is False


def test_the_rest_of_a_leg_begins_after_the_line_the_walker_is_on() -> None:
    """The gate_1 leg (four waypoints) stopped partway up its second line: planned again, it
    goes on from there, not back to its first waypoint."""
    gate_1 = COURSE_LEGS[1]
    assert gate_1.waypoints[0] == (3.2, -38.0)
    assert rest_of_leg(gate_1, (1.6, -38.0), (1.6, -38.0)) == gate_1
    assert rest_of_leg(gate_1, (1.6, -38.0), (3.25, -31.97)).waypoints == gate_1.waypoints[1:]
    assert rest_of_leg(gate_1, (1.6, -38.0), (0.6, -23.0)).waypoints == gate_1.waypoints[3:]


def test_a_resumed_leg_is_planned_from_rest() -> None:
    """After a look the rest of the leg is planned facing its next waypoint from rest."""
    rest, gait = resumed_leg(COURSE_LEGS[1], RouteGait(), (1.6, -38.0), (3.25, -31.97))
    assert rest.waypoints == COURSE_LEGS[1].waypoints[1:]
    assert gait.start_in_place and gait.inside_in_place
    assert gait.stride_m == RouteGait().stride_m
