"""DRCSim's mode-switching demo offline (asi/mode_switching.py through the stepping loop,
test/support/mode_switching_run.py), from the default launch's start.

Mixed control as DRC-era demos used it: the user's PID at zeros with kp_velocity 50, the
stand-prep pose, StandPrep, Stand, the neck and arms back under the PID while Stand
balances, a four-step Walk sent once, then every joint back to the PID. It runs through
because the velocity gain is the joints' damping, as in DRCSim 2.7 (sim/velocity_damping.py):
applied as 2.5.2's explicit torque the robot slid 0.3 m and fell in the stand-prep pose (5.7
s); without a velocity gain the stand-prep pose falls as well (planted below).
"""

from __future__ import annotations

import pytest

from support.mode_switching_run import START_S, run_mode_switching
from tutorial_atlas_control.asi import Behavior

#: Offline (no ROS, no claim about time): `make test` runs it at the lowest priority beside
#: the serial tests, on the CPU they leave idle.
pytestmark = pytest.mark.offline

#: The seeds here; `make bench`'s walking section runs 8 (mode_switching_*).
SEEDS = (None, 0)
#: The pelvis stays above this from the first command to the end (m).
PELVIS_ABOVE_M = 0.8
#: The walk's four 0.25 m steps take the pelvis at least this far (m).
WALKED_AT_LEAST_M = 0.6
#: What the library reports, in order: User (the hold, then the PID), StandPrep, Stand,
#: Walk, Stand after it, User at the end.
BEHAVIOURS = [Behavior.USER, Behavior.STAND_PREP, Behavior.STAND, Behavior.WALK, Behavior.STAND,
              Behavior.USER]


@pytest.mark.parametrize('seed', SEEDS)
def test_the_mode_switching_demo_runs_through_without_a_fall(seed: int | None) -> None:
    run = run_mode_switching(seed)
    assert run.fell_at_s is None, run
    assert run.lowest_pelvis_m > PELVIS_ABOVE_M, run
    assert run.behaviours == BEHAVIOURS, run
    assert run.at_walk is not None and run.at_end is not None
    assert run.at_end[0] - run.at_walk[0] > WALKED_AT_LEAST_M, run
    assert run.refused == [], run.refused


def test_without_the_velocity_gain_the_stand_prep_pose_falls() -> None:
    """The demo's stand-prep pose under the PID alone, from straight legs: down before
    StandPrep is asked for (the gain's damping is what holds it)."""
    run = run_mode_switching(kp_velocity=0.0)
    assert run.fell_at_s is not None and run.fell_at_s < START_S + 4.0, run
