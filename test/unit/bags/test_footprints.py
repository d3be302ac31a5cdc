"""A recorded walk in numbers: landings found in a foot's path, matched with the steps asked
for, and the demo's lines and plot."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.bags.footprints import (
    LANDING_SETTLE_S,
    Landing,
    StepTarget,
    WalkSummary,
    landings,
    plot_footprints,
    walk_lines,
)

RATE_HZ = 200.0
#: The foot link's height (m) standing flat, in these paths.
STANDING_M = 0.08


def _foot_path(stances: list[tuple[float, float, float, float]],
               lift_m: float = 0.05) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A foot standing at (x, y, yaw) from t0 to t1 for each stance, swinging (lifted, moving
    straight) between them: times, positions and yaws at RATE_HZ."""
    times, positions, yaws = [], [], []
    for number, (start_s, x, y, yaw) in enumerate(stances):
        end_s = stances[number + 1][0] - 0.3 if number + 1 < len(stances) else start_s + 0.5
        t = np.arange(start_s, end_s, 1 / RATE_HZ)
        times.append(t)
        positions.append(np.column_stack([np.full_like(t, x), np.full_like(t, y),
                                          np.full_like(t, STANDING_M)]))
        yaws.append(np.full_like(t, yaw))
        if number + 1 < len(stances):
            swing = np.arange(end_s, stances[number + 1][0], 1 / RATE_HZ)
            fraction = (swing - end_s) / 0.3
            nx, ny = stances[number + 1][1:3]
            times.append(swing)
            positions.append(np.column_stack([x + fraction * (nx - x), y + fraction * (ny - y),
                                              STANDING_M + lift_m * np.sin(np.pi * fraction)]))
            yaws.append(np.full_like(swing, yaw))
    return np.concatenate(times), np.concatenate(positions), np.concatenate(yaws)


def test_each_time_the_foot_comes_down_again_is_a_landing_where_it_settled() -> None:
    t, position, yaw = _foot_path([(0.0, 0.0, 0.1, 0.0), (1.0, 0.25, 0.1, 0.05),
                                   (2.0, 0.75, 0.12, 0.1)])
    found = landings(0, t, position, yaw, STANDING_M)
    # down: within PLANTED_HEIGHT_M of the ground, a few ms before the swing ends
    assert [each.t_s for each in found] == pytest.approx([1.0, 2.0], abs=0.02)
    assert [(each.x_m, each.y_m, each.yaw_rad) for each in found] == [
        (0.25, 0.1, 0.05), (0.75, 0.12, 0.1)]
    assert all(each.foot_index == 0 for each in found)


def test_the_pose_is_read_once_the_sole_settled() -> None:
    t, position, yaw = _foot_path([(0.0, 0.0, 0.1, 0.0), (1.0, 0.25, 0.1, 0.0)])
    landed = t >= 1.0
    position[landed, 0] += np.where(t[landed] < 1.0 + LANDING_SETTLE_S / 2, 0.02, 0.0)
    assert landings(0, t, position, yaw, STANDING_M)[0].x_m == 0.25  # not the bounce's 0.27


def test_a_scuff_is_not_a_landing_and_a_walk_may_start_lifted() -> None:
    t, position, yaw = _foot_path([(0.0, 0.0, 0.1, 0.0), (1.0, 0.25, 0.1, 0.0)])
    scuff = (t > 0.8) & (t < 0.85)
    position[scuff, 2] = STANDING_M  # down for 50 ms in the swing
    assert len(landings(0, t, position, yaw, STANDING_M)) == 1
    lifted = t > 0.75  # the record starts in the swing: the first stance is a step
    assert len(landings(1, t[lifted], position[lifted], yaw[lifted], STANDING_M)) == 1
    assert landings(1, t[:0], position[:0], yaw[:0], STANDING_M) == []


def _summary(fell: bool = False) -> WalkSummary:
    placements = [
        (StepTarget(1, 0, 0.25, 0.12, 0.0), Landing(0, 1.0, 0.27, 0.12, 0.02)),
        (StepTarget(2, 1, 0.50, -0.12, 0.0), Landing(1, 1.6, 0.50, -0.09, -0.05)),
        (StepTarget(3, 0, 0.75, 0.12, 0.0), None),
    ]
    return WalkSummary(placements, 0.61, fell, 0.35 if fell else 0.88,
                       np.array([[0.0, 0.0], [0.3, 0.01], [0.61, 0.0]]), path_m=0.63)


def test_the_lines_say_steps_path_placement_and_falls() -> None:
    summary = _summary()
    assert summary.steps_taken == 2
    assert summary.worst_placement == pytest.approx((0.03, 0.05))
    # In each step's frame: (+2 cm ahead, 0) and (0, +3 cm left): the mean (1, 1.5) cm, each
    # 1.80 cm from it.
    assert summary.placement_bias_m == pytest.approx((0.01, 0.015))
    assert summary.placement_scatter_m == pytest.approx(np.hypot(0.01, 0.015))
    assert walk_lines(summary) == [
        'walk: 2 of 3 steps taken; walked 0.63 m, ended 0.61 m from where the walk began',
        'walk: landings 1.0 cm ahead and 1.5 cm left of the steps asked for on average, '
        'scatter 1.8 cm; worst placement 3.0 cm and 0.050 rad from the step asked for',
        'walk: no fall (lowest pelvis 0.880 m)']
    assert walk_lines(_summary(fell=True))[-1] == 'walk: FELL (lowest pelvis 0.350 m)'


def test_the_bias_is_taken_in_each_steps_frame() -> None:
    """Round a circle a world-frame mean cancels out; in each step's frame it does not."""
    placements = [(StepTarget(k, k % 2, 0.0, 0.0, yaw),
                   Landing(k % 2, float(k), 0.02 * np.cos(yaw), 0.02 * np.sin(yaw), yaw))
                  for k, yaw in enumerate(np.linspace(0.0, 2 * np.pi, 8, endpoint=False))]
    summary = WalkSummary(placements, 0.0, False, 0.88, np.zeros((1, 2)))
    assert summary.placement_bias_m == pytest.approx((0.02, 0.0), abs=1e-12)
    assert summary.placement_scatter_m == pytest.approx(0.0, abs=1e-12)


def test_the_footprints_are_plotted(tmp_path: Path) -> None:
    path = plot_footprints(_summary(), tmp_path / 'walk.footprints.png')
    assert path.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    assert path.stat().st_size > 10_000
