"""The rules that end Walk's and Step's phases, without MuJoCo: a timed phase ends once at
rest after its shortest time or at its longest, a swing at touchdown after its duration or
late_touchdown_s past it, and a swing runs from the sole where it lifts to the step's pose."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from tutorial_atlas_control.walking.footsteps import Footstep
from tutorial_atlas_control.walking.phases import PhaseClock, settled, swing_to, touched_down
from tutorial_atlas_control.walking.status_flags import STEPPING, SWAYING


def test_the_clock_counts_from_the_phase_entered() -> None:
    clock = PhaseClock(SWAYING, 1.0)
    assert clock.elapsed_s(1.25) == pytest.approx(0.25)
    clock.enter(STEPPING, 2.0)
    assert (clock.phase, clock.elapsed_s(2.5)) == (STEPPING, 0.5)


@pytest.mark.parametrize(('elapsed_s', 'at_rest', 'ends'), [
    (0.9, True, False),    # at rest, but not yet its shortest time
    (1.0, True, True),     # its shortest time, at rest
    (1.5, False, False),   # not at rest, not yet its longest
    (2.0, False, True),    # its longest: ends at rest or not
])
def test_a_timed_phase_ends_at_rest_after_its_shortest_time_or_at_its_longest(
        elapsed_s: float, at_rest: bool, ends: bool) -> None:
    assert settled(elapsed_s, 1.0, 2.0, at_rest) is ends


@pytest.mark.parametrize(('touching', 'swung_s', 'ends'), [
    (True, 0.62, False),   # down early: the swing runs its duration
    (True, 0.63, True),    # touchdown
    (False, 0.8, False),   # late, still in the air
    (False, 1.03, True),   # late_touchdown_s past its duration: put down where it is
])
def test_a_swing_ends_at_touchdown_or_late(touching: bool, swung_s: float, ends: bool) -> None:
    assert touched_down(touching, swung_s, 0.63, 0.4) is ends


def test_a_swing_runs_from_the_lifted_sole_to_the_steps_whole_pose() -> None:
    yaw = 0.3
    sole = np.array([[np.cos(yaw), -np.sin(yaw), 0.0], [np.sin(yaw), np.cos(yaw), 0.0],
                     [0.0, 0.0, 1.0]])
    state = SimpleNamespace(sole_centres=np.array([[0.0, 0.12, 0.0], [0.1, -0.12, 0.001]]),
                            sole_rotations=np.array([np.eye(3), sole]))
    step = Footstep(1, 1, 0.4, -0.12, 0.5, z_m=0.15)
    path = swing_to(state, step, 0.7)  # type: ignore[arg-type]
    np.testing.assert_array_equal(path.start, [0.1, -0.12, 0.001])
    np.testing.assert_array_equal(path.end, [0.4, -0.12, 0.15])
    assert (path.start_yaw_rad, path.end_yaw_rad, path.duration_s) == (
        pytest.approx(yaw), 0.5, 0.7)
    state.sole_centres[1, 0] = 9.0
    assert path.start[0] == 0.1  # a copy: the estimate's arrays are not kept
