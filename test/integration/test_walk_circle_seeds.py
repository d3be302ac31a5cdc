"""The 2 m circle over perturbed starts: its first tenth (6 of a turn's 60 streamed steps,
turning 0.63 rad) from each of 8 seeds.

test_walking.py keeps one deterministic run of a turn; this holds the
circle over seeds (walking/start_noise.py: 5 mrad and 5 mrad/s on every joint), the
assertions on the fractions, their messages naming the seeds that failed. A tenth of a turn,
not a turn, for make test's 15 minutes: a whole turn over 8 seeds (measured once 8 of 8
within 2.5 cm, 0.034 rad, back within 0.3 m of the start) cost 221 CPU s, a third of the
offline part; it is `make bench`'s walking section (walk_circle_*). About 25 CPU s.
"""

from __future__ import annotations

import numpy as np
import pytest

from tutorial_atlas_control.walking import circle_steps
from tutorial_atlas_control.walking.walk_trial import WalkTrial, walk_started_s, walk_trial

#: Offline (no ROS, no claim about time): `make test` runs it at the lowest priority beside
#: the serial tests, on the CPU they leave idle.
pytestmark = pytest.mark.offline

SEEDS = range(8)
#: The circle: radius (m), steps a turn, feet apart (m); the steps walked (a tenth of it) and
#: how far round the pelvis must turn (rad).
RADIUS_M = 2.0
STEPS_A_TURN = 60
WIDTH_M = 0.3
STEPS = 6
TURNED_AT_LEAST_RAD = 0.45
#: The README's "every landing within about 3 cm" (m), the issue's 0.1 rad.
LANDING_WITHIN_M = 0.03
LANDING_YAW_WITHIN_RAD = 0.1
PELVIS_ABOVE_M = 0.8
#: Sim time after the last step (s): the catch (at least 0.6 s), then Stand.
AFTER_S = 1.5


@pytest.fixture(scope='module')
def turns() -> dict[int, WalkTrial]:
    plan = circle_steps(RADIUS_M, STEPS_A_TURN, 1, width_m=WIDTH_M)[:STEPS]
    duration_s = walk_started_s() + len(plan) * plan[0].duration_s + AFTER_S
    trials = {seed: walk_trial(plan, duration_s, streaming=True, seed=seed) for seed in SEEDS}
    print(f'circle: worst landing {max(t.worst_landing_m for t in trials.values()):.4f} m, '
          f'{max(max(x.yaw_error_rad for x in t.landings) for t in trials.values()):.4f} rad, '
          f'lowest pelvis {min(t.lowest_pelvis_m for t in trials.values()):.4f} m')
    return trials


def turned_round(trial: WalkTrial) -> bool:
    """The pelvis turned a tenth of the way round: its heading at the end (from its path
    round the centre at (0, R)) at least TURNED_AT_LEAST_RAD from the start's."""
    x, y = float(trial.pelvis_end[0]), float(trial.pelvis_end[1])
    return float(np.arctan2(x, RADIUS_M - y)) % (2 * np.pi) >= TURNED_AT_LEAST_RAD


def test_eight_of_eight_seeds_walk_a_tenth_of_the_circle_landing_within_3_cm(
        turns: dict[int, WalkTrial]) -> None:
    def ok(trial: WalkTrial) -> bool:
        return (not trial.fell and trial.steps == STEPS and trial.walk_ended_s is not None
                and trial.lowest_pelvis_m > PELVIS_ABOVE_M and turned_round(trial)
                and all(landing.error_m < LANDING_WITHIN_M
                        and landing.yaw_error_rad < LANDING_YAW_WITHIN_RAD
                        for landing in trial.landings))
    bad = [seed for seed, trial in turns.items() if not ok(trial)]
    assert len(turns) - len(bad) == 8, (
        f'{len(turns) - len(bad)} of {len(turns)} seeds walked the tenth within 3 cm; failed: '
        + ', '.join(f'seed {seed} (fell={turns[seed].fell}, {turns[seed].steps} steps, worst '
                    f'landing {turns[seed].worst_landing_m:.3f} m)' for seed in bad))
    ends = {tuple(round(float(v), 9) for v in trial.pelvis_end) for trial in turns.values()}
    assert len(ends) == len(turns)  # the seeds perturb
