"""trajectories/Stepping.yaml's step_and_stand and two_steps, played offline with their gains:
the README's figures (and Stepping.yaml's header's), to their printed precision. An offline
run is deterministic: the figures are exact, not held to a live run's tolerance or to the
issue's goals (0.15 m forward, pelvis above 0.8 m), which they meet."""

from __future__ import annotations

from pathlib import Path

import pytest

from tutorial_atlas_control.search.runs import run_one
from tutorial_atlas_control.search.sweep import SweepInputs, build_specs, run_sweep

#: Offline (no ROS, no claim about time): `make test` runs it at the lowest priority beside
#: the serial tests, on the CPU they leave idle.
pytestmark = pytest.mark.offline

REPO = Path(__file__).resolve().parents[2]
STEPPING = REPO / 'trajectories' / 'Stepping.yaml'
GAINS = REPO / 'config' / 'stepping_gains.yaml'
STAND_S = 5.0
#: README: "the right foot lifts 0.064 m and lands 0.264 m further forward, and the robot
#: stands the 5 s after with the pelvis at 0.92 m" (Stepping.yaml: 0.920 m).
STEP_LIFT_M = 0.064
STEP_FORWARD_M = 0.264
STEP_PELVIS_END_M = 0.920
#: README: over gains and timing x0.9/1/1.1 (and pushes), "all with the foot 0.21 m or more
#: forward"; the four one-off variants are among those that stay up.
ROBUST_FORWARD_M = 0.21
#: README: "with every command 0-20 ms late, 19 of 20" (sweep.py --latency-ms 0:20 --repeat
#: 20, seeds 0-19); Stepping.yaml: "foot 0.238 m or more forward".
LATE_DRAWS, LATE_STAND, LATE_FORWARD_M = 20, 19, 0.238
#: Put down: the foot's height at the end, against where it started (m).
DOWN_WITHIN_M = 0.01
#: README: two_steps' "left foot ends 0.50 m forward, 0.14 m past the right"; Stepping.yaml:
#: the left foot rises to 0.063 m, the right ends 0.361 m forward, the pelvis at 0.872 m at
#: the end (0.811 m at least).
TWO_LEFT_FORWARD_M, TWO_PAST_M, TWO_RIGHT_FORWARD_M = 0.50, 0.14, 0.361
TWO_LEFT_LIFT_M = 0.063
TWO_PELVIS_END_M, TWO_PELVIS_MIN_M = 0.872, 0.811


def test_step_and_stand_offline() -> None:
    spec, = build_specs(SweepInputs([(str(STEPPING), 'step_and_stand')], [str(GAINS)],
                                    settle_s=STAND_S))
    row = run_one(spec)
    assert row['fell'] is False, row
    assert round(row['r_foot_lift_max_m'], 3) == STEP_LIFT_M
    assert round(row['r_foot_dx_m'], 3) == STEP_FORWARD_M
    assert abs(row['r_foot_dz_end_m']) < DOWN_WITHIN_M
    assert row['stood_after_s'] == STAND_S
    assert round(row['pelvis_z_end_m'], 3) == STEP_PELVIS_END_M


def test_the_tutorial_gains_do_not_hold_it() -> None:
    """Why the gains file: with the tutorial's gains the same trajectory falls."""
    spec, = build_specs(SweepInputs([(str(STEPPING), 'step_and_stand')],
                                    [str(REPO / 'config' / 'atlas_controller.yaml')],
                                    settle_s=STAND_S))
    assert run_one(spec)['fell'] is True


def test_step_and_stand_survives_ten_percent_on_gains_or_timing() -> None:
    """What the robust search asked for: gains or timing 10 % off, one at a time, and it
    still steps and stands, the foot 0.21 m or more forward (both off together can fell it:
    Stepping.yaml says which)."""
    specs = build_specs(SweepInputs([(str(STEPPING), 'step_and_stand')], [str(GAINS)],
                                    gain_scales=(0.9, 1.1), settle_s=STAND_S))
    specs += build_specs(SweepInputs([(str(STEPPING), 'step_and_stand')], [str(GAINS)],
                                     time_scales=(0.9, 1.1), settle_s=STAND_S))
    for spec in specs:
        row = run_one(spec)
        label = f'gains x{spec.gain_scale}, timing x{spec.time_scale}'
        assert row['fell'] is False, label
        assert round(row['r_foot_dx_m'], 2) >= ROBUST_FORWARD_M, label


def test_step_and_stand_survives_late_commands() -> None:
    """What keeps it up live on a busy machine: every command 0-20 ms late, the README's 20
    seeded draws: 19 step and stand, the foot 0.238 m or more forward (QuickStep.yaml's
    quick_step, the search's start, fails most of them)."""
    specs = build_specs(SweepInputs([(str(STEPPING), 'step_and_stand')], [str(GAINS)],
                                    settle_s=STAND_S, latency_steps=(0, 20),
                                    repeats=LATE_DRAWS))
    # One worker, in this process: with a Dask cluster of two the test took 83 CPU s, here
    # 52; the draws are seeded, the table the same on any number of workers (test_sweep.py).
    rows = run_sweep(specs, workers=1, progress=False).rows
    stood = [row for row in rows if not row['fell']]
    assert len(stood) == LATE_STAND, [row['seed'] for row in rows if row['fell']]
    assert round(min(row['r_foot_dx_m'] for row in stood), 3) == LATE_FORWARD_M


def test_two_steps_offline() -> None:
    """The stretch goal's start (two steps in a row, Stepping.yaml's two_steps): after
    step_and_stand's right step, the left foot lifts, swings past the right one and is put
    down, and the robot stands the 5 s after. Offline and as written only: its header gives
    how rarely it survives gains, timing or latency off."""
    spec, = build_specs(SweepInputs([(str(STEPPING), 'two_steps')], [str(GAINS)],
                                    settle_s=STAND_S))
    row = run_one(spec)
    assert row['fell'] is False, row
    assert round(row['l_foot_dx_m'], 2) == TWO_LEFT_FORWARD_M
    assert round(row['l_foot_dx_m'] - row['r_foot_dx_m'], 2) == TWO_PAST_M
    assert round(row['r_foot_dx_m'], 3) == TWO_RIGHT_FORWARD_M
    assert round(row['l_foot_lift_max_m'], 3) == TWO_LEFT_LIFT_M
    for foot in ('r', 'l'):
        assert abs(row[f'{foot}_foot_dz_end_m']) < DOWN_WITHIN_M, foot
    assert row['stood_after_s'] == STAND_S
    assert round(row['pelvis_z_end_m'], 3) == TWO_PELVIS_END_M
    assert round(row['pelvis_z_min_m'], 3) == TWO_PELVIS_MIN_M
