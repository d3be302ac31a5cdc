"""trajectories/Stepping.yaml's step_and_stand (found by search.py, issue 27), played offline
with its gains: the right foot lifts, lands at least 0.15 m further forward, and the robot
stands the 5 s after with the pelvis above 0.8 m."""

from __future__ import annotations

from pathlib import Path

from tutorial_atlas_control.search.runs import run_one
from tutorial_atlas_control.search.sweep import SweepInputs, build_specs

REPO = Path(__file__).resolve().parents[2]
STEPPING = REPO / 'trajectories' / 'Stepping.yaml'
GAINS = REPO / 'config' / 'stepping_gains.yaml'
#: The issue's goals.
FORWARD_M = 0.15
STAND_S = 5.0
PELVIS_ABOVE_M = 0.8
#: Lifted, not slid: the foot's highest point above where it stood (m).
LIFTED_M = 0.03
#: Of ten runs with every command 0-20 ms late, at least this many step and stand.
LATE_PASSES = 8
#: Put down: the foot's height at the end, against where it started (m).
DOWN_WITHIN_M = 0.01
#: two_steps: the left foot ends at least this much further forward than the right (m).
PAST_M = 0.1


def test_step_and_stand_offline() -> None:
    spec, = build_specs(SweepInputs([(str(STEPPING), 'step_and_stand')], [str(GAINS)],
                                    settle_s=STAND_S))
    row = run_one(spec)
    assert row['fell'] is False, row
    assert row['r_foot_lift_max_m'] > LIFTED_M
    assert row['r_foot_dx_m'] >= FORWARD_M
    assert abs(row['r_foot_dz_end_m']) < DOWN_WITHIN_M
    assert row['stood_after_s'] >= STAND_S
    assert row['pelvis_z_min_m'] > PELVIS_ABOVE_M


def test_the_tutorial_gains_do_not_hold_it() -> None:
    """Why the gains file: with the tutorial's gains the same trajectory falls."""
    spec, = build_specs(SweepInputs([(str(STEPPING), 'step_and_stand')],
                                    [str(REPO / 'config' / 'atlas_controller.yaml')],
                                    settle_s=STAND_S))
    assert run_one(spec)['fell'] is True


def test_step_and_stand_survives_ten_percent_on_gains_or_timing() -> None:
    """What the robust search asked for: gains or timing 10 % off, one at a time, and it
    still steps and stands (both off together can fell it: Stepping.yaml says which)."""
    specs = build_specs(SweepInputs([(str(STEPPING), 'step_and_stand')], [str(GAINS)],
                                    gain_scales=(0.9, 1.1), settle_s=STAND_S))
    specs += build_specs(SweepInputs([(str(STEPPING), 'step_and_stand')], [str(GAINS)],
                                     time_scales=(0.9, 1.1), settle_s=STAND_S))
    for spec in specs:
        row = run_one(spec)
        label = f'gains x{spec.gain_scale}, timing x{spec.time_scale}'
        assert row['fell'] is False, label
        assert row['r_foot_dx_m'] >= FORWARD_M, label
        assert row['pelvis_z_min_m'] > PELVIS_ABOVE_M, label


def test_step_and_stand_survives_late_commands() -> None:
    """What keeps it up live on a busy machine: every command 0-20 ms late, ten seeded draws
    (not the search's four); at least LATE_PASSES of them step and stand (measured: 9 of 10;
    QuickStep.yaml's quick_step, the search's start: 3 of 10)."""
    specs = build_specs(SweepInputs([(str(STEPPING), 'step_and_stand')], [str(GAINS)],
                                    settle_s=STAND_S, seed=100, latency_steps=(0, 20),
                                    repeats=10))
    passed = []
    for spec in specs:
        row = run_one(spec)
        passed.append(not row['fell'] and row['r_foot_dx_m'] >= FORWARD_M
                      and row['pelvis_z_min_m'] > PELVIS_ABOVE_M)
    assert sum(passed) >= LATE_PASSES, passed


def test_two_steps_offline() -> None:
    """The stretch goal's start (two steps in a row, Stepping.yaml's two_steps): after
    step_and_stand's right step, the left foot lifts, swings past the right one and is put
    down, and the robot stands the 5 s after. Offline and as written only: its header gives
    how rarely it survives gains, timing or latency off."""
    spec, = build_specs(SweepInputs([(str(STEPPING), 'two_steps')], [str(GAINS)],
                                    settle_s=STAND_S))
    row = run_one(spec)
    assert row['fell'] is False, row
    assert row['r_foot_dx_m'] >= FORWARD_M
    assert row['l_foot_lift_max_m'] > LIFTED_M
    assert row['l_foot_dx_m'] > row['r_foot_dx_m'] + PAST_M
    for foot in ('r', 'l'):
        assert abs(row[f'{foot}_foot_dz_end_m']) < DOWN_WITHIN_M, foot
    assert row['stood_after_s'] >= STAND_S
    assert row['pelvis_z_end_m'] > PELVIS_ABOVE_M
