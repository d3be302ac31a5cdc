"""Footsteps: their checks, DRCSim's fixed queue, and the straight and circular plans."""

from __future__ import annotations

import math
import re

import pytest

from tutorial_atlas_control.walking.footsteps import (
    DRCSIM_WALK_QUEUE,
    LEFT,
    RIGHT,
    Footstep,
    circle_steps,
    straight_steps,
    window,
    wrap_angle,
)


def test_drcsim_walk_queue_is_atlas_plugins() -> None:
    assert [(s.step_index, s.foot_index, s.x_m, s.y_m, s.yaw_rad, s.duration_s)
            for s in DRCSIM_WALK_QUEUE] == [
        (1, LEFT, 0.2, 0.12, 0.0, 0.63), (2, RIGHT, 0.4, -0.12, 0.0, 0.63),
        (3, LEFT, 0.6, 0.12, 0.0, 0.63), (4, RIGHT, 0.8, -0.12, 0.0, 0.63)]


@pytest.mark.parametrize('fields, message', [
    ((1, 2, 0.0, 0.0, 0.0), 'foot_index 2 is not 0 (left) or 1 (right)'),
    ((1, 0, math.nan, 0.0, 0.0), 'not finite'),
    ((1, 0, 0.0, 0.0, math.inf), 'not finite'),
    ((1, 0, 0.0, 0.0, 0.0, 0.0), 'duration 0.0 s is not positive'),
    ((1, 0, 0.0, 0.0, 0.0, 0.63, math.nan), 'not finite'),
    ((3, 0, 0.0, 0.0, 0.0, 0.63, 0.0, (0.0, 0.0, 2.0)),
     'step 3: surface normal (0.0, 0.0, 2.0) is not a unit vector pointing up'),
    ((3, 0, 0.0, 0.0, 0.0, 0.63, 0.0, (0.0, 0.0, -1.0)), 'pointing up'),
])
def test_a_bad_step_is_refused_naming_it(fields: tuple, message: str) -> None:
    with pytest.raises(ValueError, match=re.escape(message)):
        Footstep(*fields)


def test_a_step_is_on_the_ground_unless_it_says_otherwise() -> None:
    """A DRC-era client's step (x, y, yaw) lands on the ground the robot starts on; a step
    onto a 16 degree slope 0.2 m up keeps its height and the slope's normal."""
    flat = Footstep(1, LEFT, 0.3, 0.12, 0.0)
    assert (flat.z_m, flat.normal) == (0.0, (0.0, 0.0, 1.0))
    tilt = math.radians(16.0)
    normal = (-math.sin(tilt), 0.0, math.cos(tilt))
    up = Footstep(2, RIGHT, 0.6, -0.12, 0.0, z_m=0.2, normal=normal)
    assert (up.z_m, up.normal) == (0.2, normal)


def test_straight_steps_alternate_and_end_side_by_side() -> None:
    steps = straight_steps(5, 0.25, width_m=0.3)
    assert [s.foot_index for s in steps] == [LEFT, RIGHT, LEFT, RIGHT, LEFT]
    assert [s.x_m for s in steps] == [0.25, 0.5, 0.75, 1.0, 1.0]
    assert [s.y_m for s in steps] == [0.15, -0.15, 0.15, -0.15, 0.15]
    assert [s.step_index for s in steps] == [1, 2, 3, 4, 5]


def test_circle_keeps_each_foot_on_its_radius_and_comes_round() -> None:
    radius, width = 2.0, 0.3
    steps = circle_steps(radius, 60, circles=2, width_m=width)
    assert len(steps) == 120
    for step in steps:
        distance = math.hypot(step.x_m, step.y_m - radius)
        inner = step.foot_index == LEFT
        assert distance == pytest.approx(radius - width / 2 if inner else radius + width / 2)
        # Heading along the path: the foot's radius is perpendicular to it.
        assert math.cos(step.yaw_rad) * step.x_m + math.sin(step.yaw_rad) * (
            step.y_m - radius) == pytest.approx(0.0, abs=1e-12)
    # One turn later the walker is back where it began (the feet side by side at y = -+w/2).
    last_of_first = steps[59]
    assert (last_of_first.x_m, last_of_first.y_m) == pytest.approx((0.0, -width / 2), abs=1e-12)
    assert last_of_first.yaw_rad == pytest.approx(0.0, abs=1e-12)


def test_circle_refuses_a_radius_inside_the_stance() -> None:
    with pytest.raises(ValueError, match='would cross the centre'):
        circle_steps(0.1, 60)


def test_a_streaming_window_is_four_steps_from_the_index_needed() -> None:
    plan = straight_steps(6, 0.2)
    assert [s.step_index for s in window(plan, 1)] == [1, 2, 3, 4]
    assert [s.step_index for s in window(plan, 5)] == [5, 6]
    assert window(plan, 7) == []


def test_wrap_angle() -> None:
    assert wrap_angle(math.pi) == pytest.approx(-math.pi)
    assert wrap_angle(2.0 * math.pi + 0.1) == pytest.approx(0.1)
    assert wrap_angle(-0.1) == pytest.approx(-0.1)
