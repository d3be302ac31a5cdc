"""A route's footsteps: strides, turns, the first foot, the feet side by side at the end, and
every step within what the legs reach from the one before."""

from __future__ import annotations

import math

import pytest

from tutorial_atlas_control.walking import WalkingError
from tutorial_atlas_control.walking.footsteps import LEFT, RIGHT, Footstep, wrap_angle
from tutorial_atlas_control.walking.ground_strides import GroundGait, sole_fit
from tutorial_atlas_control.walking.route import (
    RouteGait,
    centre_line_xy,
    feet_origin,
    route_steps,
)
from tutorial_atlas_control.walking.step_queue import clamp_step


def centre_after(steps: list[Footstep]) -> tuple[float, float]:
    """The midpoint of the last two soles."""
    a, b = steps[-2], steps[-1]
    return (a.x_m + b.x_m) / 2, (a.y_m + b.y_m) / 2


def centre_of(step: Footstep) -> tuple[float, float, float]:
    """The centre line's point and heading a step was placed from (half the width aside)."""
    half = (0.12 if step.foot_index == LEFT else -0.12)
    return (step.x_m + half * math.sin(step.yaw_rad), step.y_m - half * math.cos(step.yaw_rad),
            step.yaw_rad)


def test_a_straight_route_strides_equally_and_ends_with_the_feet_side_by_side() -> None:
    steps = route_steps((1.0, 2.0), 0.0, [(1.6, 2.0)])
    assert [s.step_index for s in steps] == [1, 2, 3, 4, 5]
    assert [s.foot_index for s in steps] == [LEFT, RIGHT, LEFT, RIGHT, LEFT]
    assert [round(s.x_m, 9) for s in steps] == [1.15, 1.3, 1.45, 1.6, 1.6]
    assert [round(s.y_m, 9) for s in steps] == [2.12, 1.88, 2.12, 1.88, 2.12]
    assert all(s.yaw_rad == 0.0 and s.duration_s == 0.63 for s in steps)


def test_a_stride_is_never_longer_than_the_gaits() -> None:
    steps = route_steps((0.0, 0.0), 0.0, [(1.0, 0.0)], RouteGait(stride_m=0.3))
    strides = [b.x_m - a.x_m for a, b in zip(steps, steps[1:-1])]
    assert len(steps) == 5  # four strides of 0.25 m, then the feet together
    assert strides == pytest.approx([0.25] * 3)


@pytest.mark.parametrize('goal, first_foot, turn', [
    ((0.0, 3.0), LEFT, math.pi / 2), ((0.0, -3.0), RIGHT, -math.pi / 2)])
def test_a_turn_starts_with_the_foot_on_its_side_and_turns_at_most_a_step_each(
        goal: tuple[float, float], first_foot: int, turn: float) -> None:
    steps = route_steps((0.0, 0.0), 0.0, [goal])
    assert steps[0].foot_index == first_foot
    headings = [0.0] + [s.yaw_rad for s in steps]
    assert max(abs(wrap_angle(b - a)) for a, b in zip(headings, headings[1:])) <= 0.2 + 1e-12
    assert abs(wrap_angle(steps[-1].yaw_rad - turn)) < 0.2  # the turn moved the centre on
    assert centre_after(steps) == pytest.approx(goal, abs=1e-9)


def test_turning_in_place_faces_the_waypoint_exactly() -> None:
    steps = route_steps((0.0, 0.0), 0.0, [(0.0, 1.0)], RouteGait(turn_stride_m=0.0))
    assert [round(s.yaw_rad, 9) for s in steps[:8]] == [
        round(min(0.2 * k, math.pi / 2), 9) for k in range(1, 9)]
    assert centre_after(steps) == pytest.approx((0.0, 1.0), abs=1e-9)
    assert steps[-1].yaw_rad == pytest.approx(math.pi / 2)


def test_a_waypoint_inside_the_turning_circle_is_refused() -> None:
    with pytest.raises(WalkingError, match=r'waypoint \(0.0, 0.3\) lies inside the turning '):
        route_steps((0.0, 0.0), 0.0, [(0.0, 0.3)])
    # The same gait turning in place (as among the rubble's blocks) reaches it.
    gait = RouteGait().turning_in_place()
    assert gait == RouteGait(turn_stride_m=0.0)
    assert centre_after(route_steps((0.0, 0.0), 0.0, [(0.0, 0.3)], gait)) == \
        pytest.approx((0.0, 0.3), abs=1e-9)


def test_a_gait_may_face_the_first_waypoint_and_any_inside_its_circle_on_the_spot() -> None:
    gait = RouteGait(start_in_place=True, inside_in_place=True)
    # Behind the walker, then 0.3 m to its left (inside the strides' turning circle), then
    # 2 m on: the first two faced on the spot, the third in turning strides.
    waypoints = [(-0.6, 0.0), (-0.6, -0.3), (-2.6, -2.3)]
    steps = route_steps((0.0, 0.0), 0.0, waypoints, gait)
    centres = [(0.0, 0.0, 0.0)] + [centre_of(step) for step in steps]
    moved = [math.dist(a[:2], b[:2]) for a, b in zip(centres, centres[1:])]
    turned = [abs(wrap_angle(b[2] - a[2])) for a, b in zip(centres, centres[1:])]
    assert max(turned) <= 0.2 + 1e-9
    spots = [k for k, (m, t) in enumerate(zip(moved, turned)) if m < 1e-9 and t > 0.05]
    assert len(spots) == 15 + 7  # 0.2 rad a step: half a turn to face the first, a quarter
    in_strides = [k for k, (m, t) in enumerate(zip(moved, turned))
                  if m == pytest.approx(gait.turn_stride_m) and t > 0.05]
    assert in_strides and min(in_strides) > max(spots)
    assert centre_after(steps) == pytest.approx(waypoints[-1], abs=1e-9)
    with pytest.raises(WalkingError, match='inside the turning circle'):
        route_steps((0.0, 0.0), 0.0, waypoints, RouteGait(start_in_place=True))


def test_a_gait_may_slow_its_strides_into_a_corner() -> None:
    waypoints = [(2.0, 0.0), (2.0, 2.0)]  # 2 m east, then a quarter turn left
    for slowdown in (0.0, 0.035):
        steps = route_steps((0.0, 0.0), 0.0, waypoints, RouteGait(turn_slowdown_m=slowdown))
        centres = [(0.0, 0.0)] + [centre_of(step)[:2] for step in steps]
        moves = [math.dist(a, b) for a, b in zip(centres, centres[1:])]
        first_turn = next(k for k, step in enumerate(steps) if step.yaw_rad > 0.05)
        into = moves[:first_turn + 1]
        drop = max(a - b for a, b in zip(into, into[1:]))
        assert drop <= 0.035 + 1e-9 if slowdown else drop > 0.06  # 0.143 -> 0.08 at once
        assert into[-1] == pytest.approx(0.08)  # the first turning step
        assert sum(into[:-1]) == pytest.approx(2.0)  # the corner where it was
        assert centre_after(steps) == pytest.approx(waypoints[-1], abs=1e-9)


def test_waypoints_in_turn_and_a_final_heading() -> None:
    steps = route_steps((-3.0, -38.0), 0.0, [(2.5, -38.0), (0.5, -24.5)],
                        final_heading_rad=math.pi / 2)
    # The final turn (1.72 rad to pi/2: one turning step) carries the centre 0.08 m on.
    assert centre_after(steps) == pytest.approx((0.5, -24.42), abs=1e-9)
    assert steps[-1].yaw_rad == pytest.approx(math.pi / 2)
    assert steps[-2].yaw_rad == pytest.approx(math.pi / 2)
    passed = [s for s in steps if abs(s.x_m - 2.5) < 0.13 and abs(s.y_m + 38.0) < 0.13]
    assert passed, 'the route goes through its first waypoint'


@pytest.mark.parametrize('start_yaw, waypoints', [
    (0.0, [(5.0, 0.0)]), (0.0, [(0.0, 2.0), (2.0, 2.0)]), (1.0, [(-1.0, -1.0)]),
    (math.pi / 2, [(0.3, 4.0), (3.0, 4.5), (3.0, 0.0)])])
def test_every_step_is_within_the_legs_reach_of_the_one_before(
        start_yaw: float, waypoints: list[tuple[float, float]]) -> None:
    steps = route_steps((0.0, 0.0), start_yaw, waypoints)
    half = RouteGait().width_m / 2
    feet = {foot: Footstep(0, foot, -side * half * math.sin(start_yaw),
                           side * half * math.cos(start_yaw), start_yaw)
            for foot, side in ((LEFT, 1.0), (RIGHT, -1.0))}
    for step in steps:
        stance = feet[1 - step.foot_index]
        clamped = clamp_step(step, stance)
        assert (clamped.x_m, clamped.y_m, clamped.yaw_rad) == pytest.approx(
            (step.x_m, step.y_m, step.yaw_rad), abs=1e-9), step
        feet[step.foot_index] = step


@pytest.mark.parametrize('waypoints, message', [
    ([], 'a route needs at least one waypoint'),
    ([(math.nan, 1.0)], 'waypoint (nan, 1.0) is not finite'),
    ([(0.0, 0.0)], 'the route from (0.0, 0.0) goes nowhere: every waypoint is there')])
def test_bad_routes_are_refused_with_a_reason(waypoints: list[tuple[float, float]],
                                              message: str) -> None:
    with pytest.raises(WalkingError) as raised:
        route_steps((0.0, 0.0), 0.0, waypoints)
    assert str(raised.value) == message


def test_a_gait_of_zero_stride_is_refused() -> None:
    with pytest.raises(WalkingError, match='a route gait needs positive finite numbers'):
        RouteGait(stride_m=0.0)


@pytest.mark.parametrize(('left_yaw', 'right_yaw', 'heading'), [
    (0.1, -0.1, 0.0), (math.pi - 0.1, -math.pi + 0.1, math.pi),
    (-math.pi + 0.05, math.pi - 0.15, -math.pi + 0.05 - 0.1)])
def test_a_route_starts_between_the_feet_facing_their_mean_heading_the_short_way(
        left_yaw: float, right_yaw: float, heading: float) -> None:
    (x, y), yaw = feet_origin((1.0, 2.12, left_yaw), (1.2, 1.88, right_yaw))
    assert (x, y) == pytest.approx((1.1, 2.0))
    assert abs(wrap_angle(yaw - heading)) < 1e-12
    assert -math.pi <= yaw <= math.pi


def test_a_route_given_level_ground_strides_as_it_does_without() -> None:
    waypoints = [(1.6, 2.0), (2.5, 3.0)]
    assert route_steps((1.0, 2.0), 0.0, waypoints, ground=lambda x, y: 0.25) \
        == route_steps((1.0, 2.0), 0.0, waypoints)


def test_a_route_down_a_ramp_given_the_ground_puts_no_sole_across_its_bends() -> None:
    grade = math.tan(math.radians(22.0))

    def ramp_down(x_m: float, y_m: float) -> float:  # north: 1.5 m down from y 1 to 2.5
        return -grade * min(max(y_m - 1.0, 0.0), 1.5)

    steps = route_steps((0.0, 0.0), math.pi / 2, [(0.0, 3.5)], ground=ramp_down)
    tolerance = GroundGait(flat_m=RouteGait().ground_flat_m)  # the route's, for a heightfield
    assert all(sole_fit(ramp_down, s.x_m, s.y_m, s.yaw_rad, tolerance).flat for s in steps)
    assert [s.foot_index for s in steps] == [LEFT, RIGHT] * (len(steps) // 2) \
        + [LEFT] * (len(steps) % 2)
    assert {s.duration_s for s in steps if 1.0 < s.y_m < 2.5} == {0.9}
    assert centre_after(steps) == pytest.approx((0.0, 3.5))
    plain = route_steps((0.0, 0.0), math.pi / 2, [(0.0, 3.5)])
    assert not all(sole_fit(ramp_down, s.x_m, s.y_m, s.yaw_rad).flat for s in plain)


def test_a_route_up_a_curved_ramp_strides_evenly_and_slowly_where_it_is_steep() -> None:
    """The course's pit ramps are a curved heightfield: its soles lie up to 14 mm off one
    plane without any bend. Planned on such a ramp (0.6 m up over 2.3 m, 22 degrees at its
    steepest), no foothold is pulled back or crossed to (each foot's swing at most two
    strides) and every step where the ramp is steeper than 15 degrees is a steep one."""
    gait = RouteGait()

    def curved(x_m: float, y_m: float) -> float:  # north, from y 1 to 3.3
        along = min(max((y_m - 1.0) / 2.3, 0.0), 1.0)
        return 0.3 * (1.0 - math.cos(math.pi * along))

    steps = route_steps((0.0, 0.0), math.pi / 2, [(0.0, 4.5)], gait, ground=curved)
    feet = [0.0, 0.0]
    for step in steps:
        swing = step.y_m - feet[step.foot_index]
        assert 0.0 <= swing <= 2 * gait.stride_m + 1e-9, step
        feet[step.foot_index] = step.y_m
        if 1.55 < step.y_m < 2.75:  # the ramp steeper than 15 degrees
            assert step.duration_s == 0.9, step
    assert centre_after(steps) == pytest.approx((0.0, 4.5))


def test_a_step_s_centre_line_point_is_the_one_its_foot_was_put_beside() -> None:
    gait = RouteGait()
    steps = route_steps((1.0, 2.0), 0.3, [(3.0, 2.5), (3.5, 4.0)], gait)
    # the last two steps put the feet side by side about the route's end
    last, before = (centre_line_xy(step, gait.width_m) for step in steps[-2:])
    assert last == pytest.approx(before, abs=1e-12)
    assert last == pytest.approx((3.5, 4.0), abs=0.15)
    # and the first stands beside the start, half the stance to its side
    x, y = centre_line_xy(steps[0], gait.width_m)
    assert math.hypot(x - 1.0, y - 2.0) < gait.stride_m
    assert math.hypot(steps[0].x_m - x, steps[0].y_m - y) == pytest.approx(gait.width_m / 2)
