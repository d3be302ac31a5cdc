"""Walking offline, deterministic: the robot standing in DRCSim's Stand pose walks a plan
of footsteps (walking/walk.py on the Stand's whole-body balance), then stands again.

DRCSim's fixed `control_mode Walk` queue (four steps of 0.2 m) and then 10 s of Stand; 20
straight steps of 0.25 m at 0.63 s each (about 0.4 m/s). The issue's bounds: every landing
within 5 cm and 0.1 rad of its target, no fall, the pelvis at least 4 m ahead after the
straight walk; and the exact figures of these runs. A client streaming its window every
step walks the same walk as one sending the plan once. The planted defect: without the limit
on the yaw moment a stance sole can take (its torsional friction) the stance foot turns
and the straight walk falls at its third step. About 13 s of CPU in all.
"""

from __future__ import annotations

import pytest

from tutorial_atlas_control.balance import STANDING_PELVIS_M
from tutorial_atlas_control.walking import DRCSIM_WALK_QUEUE, straight_steps
from tutorial_atlas_control.walking.leg_tasks import LegGains
from tutorial_atlas_control.walking.walk import WalkGains
from tutorial_atlas_control.walking.walk_trial import SETTLE_S, walk_trial

#: The issue's bounds on each landing (m, rad).
LANDING_WITHIN_M = 0.05
LANDING_YAW_WITHIN_RAD = 0.1
#: Stand after the walk (s).
STAND_AFTER_S = 10.0
#: The straight walk: steps, stride (m), and how far ahead the pelvis must end (m).
STRAIGHT_STEPS = 20
STRIDE_M = 0.25
STRAIGHT_AHEAD_M = 4.0


def test_drcsim_s_walk_queue_is_walked_and_then_stood_on() -> None:
    plan = list(DRCSIM_WALK_QUEUE)
    trial = walk_trial(plan, SETTLE_S + 3.8 + STAND_AFTER_S)
    assert not trial.fell
    assert trial.steps == 4
    assert all(landing.error_m < LANDING_WITHIN_M for landing in trial.landings)
    assert all(landing.yaw_error_rad < LANDING_YAW_WITHIN_RAD for landing in trial.landings)
    assert trial.walk_ended_s is not None
    assert SETTLE_S + 3.8 + STAND_AFTER_S - trial.walk_ended_s >= STAND_AFTER_S
    assert trial.lowest_pelvis_m > STANDING_PELVIS_M
    # This run's figures (deterministic).
    assert round(trial.worst_landing_m, 3) == 0.027
    assert round(trial.lowest_pelvis_m, 3) == 0.900
    assert float(trial.pelvis_end[0]) == pytest.approx(0.6618, abs=1e-4)
    assert trial.walk_ended_s == pytest.approx(4.726)


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


def test_a_client_streaming_its_window_every_step_walks_the_same_walk() -> None:
    """The window [next_step_index_needed, +3] sent at 1 kHz: the same landings and the
    same end, to the bit, as the plan sent once (re-requests change nothing)."""
    plan = straight_steps(6, STRIDE_M)
    once = walk_trial(plan, 7.0)
    streamed = walk_trial(plan, 7.0, streaming=True)
    assert not once.fell and once.steps == 6
    assert streamed.landings == once.landings
    assert streamed.pelvis_end.tolist() == once.pelvis_end.tolist()


def test_without_the_torsion_limit_the_stance_foot_turns_and_it_falls() -> None:
    trial = walk_trial(straight_steps(STRAIGHT_STEPS, STRIDE_M), 20.0,
                       WalkGains(legs=LegGains(torsion_m=None)))
    assert trial.fell
    assert trial.steps == 3
