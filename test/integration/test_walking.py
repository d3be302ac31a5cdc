"""Walking offline, deterministic: the robot standing in DRCSim's Stand pose walks 20
straight steps of 0.25 m at 0.63 s each (about 0.4 m/s; walking/walk.py on the Stand's
whole-body balance), then stands again. The issue's bounds: every landing within 5 cm and
0.1 rad of its target, no fall, the pelvis at least 4 m ahead; and the exact figures of
this run. The planted defect: without the limit on the yaw moment a stance sole can take
(its torsional friction) the stance foot turns and the walk falls at its third step.
DRCSim's queue, streaming and one-shot clients: test_asi_walk.py, through the interface.
About 10 s of CPU in all.
"""

from __future__ import annotations

import pytest

from tutorial_atlas_control.walking import straight_steps
from tutorial_atlas_control.walking.leg_tasks import LegGains
from tutorial_atlas_control.walking.walk import WalkGains
from tutorial_atlas_control.walking.walk_trial import walk_trial

#: Offline (no ROS, no claim about time): `make test` runs it at the lowest priority beside
#: the serial tests, on the CPU they leave idle.
pytestmark = pytest.mark.offline

#: The issue's bounds on each landing (m, rad).
LANDING_WITHIN_M = 0.05
LANDING_YAW_WITHIN_RAD = 0.1
#: The straight walk: steps, stride (m), and how far ahead the pelvis must end (m).
STRAIGHT_STEPS = 20
STRIDE_M = 0.25
STRAIGHT_AHEAD_M = 4.0


def test_twenty_straight_steps_of_a_quarter_metre() -> None:
    plan = straight_steps(STRAIGHT_STEPS, STRIDE_M)
    trial = walk_trial(plan, 20.0)
    assert not trial.fell
    assert trial.steps == STRAIGHT_STEPS
    assert all(landing.error_m < LANDING_WITHIN_M for landing in trial.landings)
    assert all(landing.yaw_error_rad < LANDING_YAW_WITHIN_RAD for landing in trial.landings)
    assert float(trial.pelvis_end[0]) >= STRAIGHT_AHEAD_M
    assert trial.walk_ended_s is not None
    # This run's figures (deterministic).
    assert round(trial.worst_landing_m, 3) == 0.030
    assert round(trial.lowest_pelvis_m, 3) == 0.900
    assert round(float(trial.pelvis_end[0]), 2) == 4.74


def test_without_the_torsion_limit_the_stance_foot_turns_and_it_falls() -> None:
    trial = walk_trial(straight_steps(STRAIGHT_STEPS, STRIDE_M), 20.0,
                       WalkGains(legs=LegGains(torsion_m=None)))
    assert trial.fell
    assert trial.steps == 3
