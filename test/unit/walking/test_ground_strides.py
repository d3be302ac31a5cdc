"""walking/ground_strides.py on made-up ground: over a 22-degree ramp between two levels
no sole lies across either bend, the ramp is walked in steep strides of the steep duration,
each bend crossed in one stride no longer than the crossing; on level ground and up 10
degrees the strides are the gait's, as straight_steps places them; up 16 degrees (over the
12 at which the course's pit exit ramp fell in mud) they are the steep ones."""

from __future__ import annotations

import math

import pytest

from tutorial_atlas_control.walking import LEFT, GroundGait, ground_steps, sole_fit, straight_steps

SLOPE = math.tan(math.radians(22.0))
FOOT_M, TOP_M = 0.6, 2.1  # the ramp's foot and top (m of x), 0.6 m of rise between them


def ramp(x_m: float, y_m: float) -> float:
    """A floor, a ramp from FOOT_M to TOP_M at 22 degrees, a platform."""
    return SLOPE * min(max(x_m - FOOT_M, 0.0), TOP_M - FOOT_M)


def test_a_sole_across_a_bend_is_not_flat_and_one_on_the_ramp_is_steep() -> None:
    across = sole_fit(ramp, FOOT_M, 0.0, 0.0)
    assert not across.flat
    on_ramp = sole_fit(ramp, 1.3, 0.12, 0.0)
    assert on_ramp.flat
    assert on_ramp.slope_rad == pytest.approx(math.radians(22.0), abs=1e-9)
    assert sole_fit(ramp, 3.0, 0.0, 0.3) == sole_fit(ramp, 0.0, 0.0, 0.0)  # level: flat, 0


@pytest.mark.parametrize('height', [ramp, lambda x, y: 0.6 - ramp(x, y)],
                         ids=['up', 'down'])
def test_no_foothold_lies_across_a_bend_and_the_ramp_is_walked_short_and_slow(height) -> None:
    gait = GroundGait()
    steps = ground_steps(3.6, height, gait)
    assert [step.foot_index for step in steps] == [LEFT, 1 - LEFT] * (len(steps) // 2) \
        + [LEFT] * (len(steps) % 2)
    for step in steps:
        assert sole_fit(height, step.x_m, step.y_m, step.yaw_rad, gait).flat, step
    feet = [0.0, 0.0]
    for step in steps:
        swing = step.x_m - feet[step.foot_index]
        other = feet[1 - step.foot_index]
        assert swing >= 0.0 and step.x_m >= other - 1e-9
        on_ramp = FOOT_M < step.x_m < TOP_M or FOOT_M < feet[step.foot_index] < TOP_M
        if on_ramp:
            assert step.duration_s == gait.steep_duration_s
            crossing = feet[step.foot_index] < FOOT_M < step.x_m \
                or feet[step.foot_index] < TOP_M < step.x_m
            assert swing <= (gait.crossing_m if crossing else 2 * gait.steep_stride_m) + 1e-9
        feet[step.foot_index] = step.x_m
    assert feet == pytest.approx([3.6, 3.6])


@pytest.mark.parametrize('degrees', [0.0, 10.0])
def test_level_ground_and_10_degrees_keep_the_gait_s_strides(degrees: float) -> None:
    grade = math.tan(math.radians(degrees))
    steps = ground_steps(2.0, lambda x, y: grade * x)
    straight = straight_steps(11, 0.2)
    assert [(s.foot_index, s.y_m, s.duration_s) for s in steps] \
        == [(s.foot_index, s.y_m, s.duration_s) for s in straight]
    assert [s.x_m for s in steps] == pytest.approx([s.x_m for s in straight])


def test_16_degrees_is_walked_in_steep_strides() -> None:
    grade = math.tan(math.radians(16.0))
    gait = GroundGait()
    steps = ground_steps(2.0, lambda x, y: grade * x, gait)
    assert {step.duration_s for step in steps} == {gait.steep_duration_s}
    assert max(b.x_m - a.x_m for a, b in zip(steps, steps[1:])) \
        == pytest.approx(gait.steep_stride_m)
