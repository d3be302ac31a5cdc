"""A way over the hills (course/hill_way.py): from gate_2 to gate_3 on ground no steeper under
the feet than the way allows (a corner dropped for the walker's turn may cross ground a
little steeper), where the straight line crosses the hills' steep sides; clear of the gate
posts; every corner one a walker turning in strides can face; refusals in one line."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tutorial_atlas_control.course import COURSE_LEGS, CourseError, leg_waypoints
from tutorial_atlas_control.course.hill_way import (
    DROP_SLACK_DEG,
    POST_CLEARANCE_M,
    REACH_M,
    STEEPEST_DEG,
    gentle_path,
    slope_deg,
)
from tutorial_atlas_control.course.rubble_way import distance_to_polygon, gate_posts
from tutorial_atlas_control.walking import RouteGait, route_steps

#: Where the gate_2 leg ends (its waypoint), the gate_3 leg's goal, and the steepest place on
#: the straight line between them (a hill's side).
GATE_2_END, GATE_3_GOAL, HILLSIDE = (0.5, -10.0), (6.0, 7.0), (2.457, -3.952)
#: The lines are checked every centimetre; the grid's cells are 5 cm, so a line may pass a
#: cell's centre by half a cell onto steeper ground: a degree of room.
ROOM_DEG = 1.0


def line_points(start: tuple[float, float], waypoints: tuple[tuple[float, float], ...],
                offset_m: float = 0.0) -> np.ndarray:
    """Points every centimetre along the straight lines start..waypoints, moved `offset_m`
    to their left."""
    corners = np.array([start, *waypoints])
    runs = []
    for a, b in zip(corners[:-1], corners[1:]):
        length = float(np.hypot(*(b - a)))
        normal = np.array([-(b - a)[1], (b - a)[0]]) / length
        runs.append(np.linspace(a, b, max(2, int(length / 0.01))) + offset_m * normal)
    return np.concatenate(runs)


def steepest_under_feet(start: tuple[float, float],
                        waypoints: tuple[tuple[float, float], ...]) -> float:
    """The steepest slope (degrees) under the way's centre line and REACH_M to either side."""
    return max(float(slope_deg(*line_points(start, waypoints, offset).T).max())
               for offset in (-REACH_M, 0.0, REACH_M))


def test_the_way_to_gate_3_keeps_to_gentle_ground_where_the_straight_line_does_not() -> None:
    waypoints = gentle_path(GATE_2_END, GATE_3_GOAL)
    assert waypoints[-1] == GATE_3_GOAL
    assert steepest_under_feet(GATE_2_END, waypoints) <= STEEPEST_DEG + DROP_SLACK_DEG + ROOM_DEG
    assert 3 <= len(waypoints) <= 14
    # The straight line, and the course's old leg through (3, -2), cross the hills' sides.
    assert steepest_under_feet(GATE_2_END, (GATE_3_GOAL,)) > 18.0
    assert steepest_under_feet(GATE_2_END, ((3.0, -2.0), GATE_3_GOAL)) > 18.0


def test_the_slope_is_gentle_before_the_hills_and_steep_on_their_sides() -> None:
    assert slope_deg(np.array(0.0), np.array(-11.5)) < 2.0
    assert slope_deg(np.array(HILLSIDE[0]), np.array(HILLSIDE[1])) > 20.0


def test_the_way_keeps_clear_of_the_gate_posts() -> None:
    points = line_points(GATE_2_END, gentle_path(GATE_2_END, GATE_3_GOAL))
    nearest = min(float(distance_to_polygon(post, points[:, 0], points[:, 1]).min())
                  for post in gate_posts())
    assert nearest >= POST_CLEARANCE_M - 0.1  # a grid cell and the shortcut's room


@pytest.mark.parametrize('seed', range(8))
def test_a_walker_turning_in_strides_can_face_every_corner(seed: int) -> None:
    rng = np.random.default_rng(seed)
    start = (GATE_2_END[0] + rng.normal(0.0, 0.15), GATE_2_END[1] + rng.normal(0.0, 0.15))
    waypoints = gentle_path(start, GATE_3_GOAL)
    steps = route_steps(start, math.pi / 2 + rng.normal(0.0, 0.05), waypoints, RouteGait())
    last = np.mean([[step.x_m, step.y_m] for step in steps[-2:]], axis=0)
    assert np.hypot(*(last - GATE_3_GOAL)) < 0.05


def test_the_gate_3_leg_is_planned_over_the_hills() -> None:
    leg = next(leg for leg in COURSE_LEGS if leg.gate == 'gate_3')
    assert leg.over_hills and not leg.clear_of_blocks
    assert leg_waypoints(leg, *GATE_2_END, ()) == gentle_path(GATE_2_END, GATE_3_GOAL)


@pytest.mark.parametrize('steepest, message', [
    (2.0, 'no way from (0.50, -10.00) to (6.00, 7.00) keeps to ground within 2 degrees'),
    (float('nan'), 'steepest_deg must be within (0, 90): nan'),
    (90.0, 'steepest_deg must be within (0, 90): 90.0')])
def test_no_gentle_way_is_one_error(steepest: float, message: str) -> None:
    with pytest.raises(CourseError) as caught:
        gentle_path(GATE_2_END, GATE_3_GOAL, steepest)
    assert str(caught.value) == message


def test_starts_a_few_centimetres_apart_share_the_way_beyond_its_first_corners() -> None:
    rng = np.random.default_rng(3)
    ways = [gentle_path((GATE_2_END[0] + dx, GATE_2_END[1] + dy), GATE_3_GOAL)
            for dx, dy in rng.uniform(-0.03, 0.03, (6, 2))]
    assert all(len(way) >= 5 for way in ways)
    spread = max(math.dist(a, b) for way in ways for a, b in zip(way[-5:], ways[0][-5:]))
    assert spread <= 0.1  # a grid cell or two of the shortening's choice


def test_the_way_is_planned_on_the_ground_it_is_given() -> None:
    """A walker's map instead of the course's terrain (the laser's, offline.course_route):
    on level ground the way is the straight line; a steep ridge across it (0.4 m high, 0.4 m
    wide, y within 2 m) is walked round, past its end."""
    start, goal = (20.0, 0.0), (26.0, 0.0)

    def level(x: np.ndarray, _y: np.ndarray) -> np.ndarray:
        return np.zeros_like(x)

    def ridge(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return np.where((np.abs(x - 23.0) < 0.2) & (np.abs(y) < 2.0), 0.4, 0.0)

    assert gentle_path(start, goal, heights=level) == (goal,)
    way = gentle_path(start, goal, heights=ridge)
    assert len(way) > 1 and max(abs(y) for _, y in way) > 2.0
    assert slope_deg(np.array([23.2]), np.array([0.0]), ridge)[0] > 45.0  # its side


def test_ground_a_map_has_not_seen_counts_as_level() -> None:
    """A map's unseen ground (NaN) is no obstacle: the way goes on into it (the walker looks
    before it gets there and plans again)."""
    start, goal = (20.0, 0.0), (26.0, 0.0)

    def seen_to_22(x: np.ndarray, _y: np.ndarray) -> np.ndarray:
        return np.where(x < 22.0, 0.0, np.nan)

    assert gentle_path(start, goal, heights=seen_to_22) == (goal,)
    assert slope_deg(np.array([23.0]), np.array([0.0]), seen_to_22)[0] == 0.0
