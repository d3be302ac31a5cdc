"""course/legs.py: the legs a course walker walks from each of DRCSim's starts, and what it
refuses."""

from __future__ import annotations

import math

import pytest

from tutorial_atlas_control.course import COURSE_LEGS, GATES, STARTS, CourseError, legs_ahead


def _past(gate_name: str, x_m: float, y_m: float) -> float:
    """How far (x, y) lies past the gate's line along its yaw (m)."""
    gate = next(gate for gate in GATES if gate.name == gate_name)
    return (x_m - gate.x_m) * math.cos(gate.yaw_rad) + (y_m - gate.y_m) * math.sin(gate.yaw_rad)


def test_every_leg_ends_past_its_gate_within_the_gate_s_posts() -> None:
    assert [leg.gate for leg in COURSE_LEGS] == [gate.name for gate in GATES]
    for leg, gate in zip(COURSE_LEGS, GATES):
        end_x, end_y = leg.waypoints[-1]
        assert 0.0 < _past(gate.name, end_x, end_y) < 1.0, leg
        across = -(end_x - gate.x_m) * math.sin(gate.yaw_rad) \
            + (end_y - gate.y_m) * math.cos(gate.yaw_rad)
        assert abs(across) < gate.width_m / 2 - 0.5, leg  # half a metre inside the posts


@pytest.mark.parametrize(('start', 'gates', 'first_waypoints'), [
    ('vrc_task_2', ['gate_0', 'gate_1', 'gate_2', 'gate_3', 'gate_4'], ((1.6, -38.0),)),
    ('vrc_task_2_mud_start', ['gate_1', 'gate_2', 'gate_3', 'gate_4'], ((0.5, -21.95),)),
    ('vrc_task_2_uneven_start', ['gate_2', 'gate_3', 'gate_4'], ((0.5, -10.0),)),
    ('vrc_task_2_rubble_start', ['gate_3', 'gate_4'], ((6.0, 7.0),))])
def test_each_start_walks_the_gates_still_ahead_of_it(start: str, gates: list[str],
                                                      first_waypoints: tuple) -> None:
    where = STARTS[start]
    legs = legs_ahead(where.x_m, where.y_m)
    assert [leg.gate for leg in legs] == gates
    assert legs[0].waypoints == first_waypoints
    assert legs[1:] == COURSE_LEGS[len(COURSE_LEGS) - len(gates) + 1:]


def test_past_gate_0_the_walk_to_gate_1_keeps_clear_of_the_pen_wall() -> None:
    legs = legs_ahead(1.6, -38.0, 'gate_1')
    assert legs == (COURSE_LEGS[1],)  # east to x 3.2 first, not straight north into the wall


def test_a_gate_behind_the_walker_leaves_nothing_to_walk() -> None:
    assert legs_ahead(1.7, -38.0, 'gate_0') == ()
    assert legs_ahead(6.0, 19.0) == ()


@pytest.mark.parametrize(('x_m', 'y_m', 'gate', 'message'), [
    (0.0, 0.0, 'gate_5', "'gate_5' is not a gate of the course (gate_0, gate_1, gate_2, "
     'gate_3, gate_4)'),
    (math.nan, -38.0, 'gate_1', 'a walker at (nan, -38.0) is nowhere')])
def test_an_unknown_gate_or_place_is_refused(x_m: float, y_m: float, gate: str,
                                             message: str) -> None:
    with pytest.raises(CourseError) as raised:
        legs_ahead(x_m, y_m, gate)
    assert str(raised.value) == message
