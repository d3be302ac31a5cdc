"""Walking offline over perturbed starts: each figure a fraction of seeds, not one run.

A walk is chaotic (once, 1 µrad of joint-angle noise decided whether 20 steps stood), so the
README's straight-walk and pushed-walk figures are held here over 8 seeds, each perturbing
the start (walking/start_noise.py: 5 mrad and 5 mrad/s of normal noise on every joint) and,
pushed, drawing the pushes' phases and sides. The assertions are on the fractions; their
messages name the seeds that failed. The seeds must perturb: 8 seeds, 8 different walks.
Planted once: the noise at 0.1 rad and 0.1 rad/s: 6 of 8 straight walks, the test fails
naming seeds 0 and 3. The circle over seeds: test_walk_circle_seeds.py; the static steps:
test_asi_walk.py. About 60 CPU s.
"""

from __future__ import annotations

from collections.abc import Callable

import pytest

from tutorial_atlas_control.walking import STEP_DURATION_S, straight_steps
from tutorial_atlas_control.walking.walk_trial import (
    WalkTrial,
    pushed_walk_trial,
    walk_started_s,
    walk_trial,
)

#: Offline (no ROS, no claim about time): `make test` runs it at the lowest priority beside
#: the serial tests, on the CPU they leave idle.
pytestmark = pytest.mark.offline

SEEDS = range(8)
#: The straight walk: steps, stride (m), the pelvis at least this far ahead at the end (m).
#: Six, not the README's twenty, for make test's 15 minutes: the twenty over 8 seeds are
#: `make bench`'s walking section (walk_straight_*). Pushed: ten steps, two pushes, and
#: the pelvis this far ahead (m).
STEPS = 6
STRIDE_M = 0.25
AHEAD_M = 1.2
PUSHED_STEPS = 10
PUSHED_AHEAD_M = 2.0
#: The landings' mean error along the step (m), the issue's bound on their bias.
LANDING_BIAS_BELOW_M = 0.005
#: The README's "every landing within about 3 cm" (m), the issue's 0.1 rad.
LANDING_WITHIN_M = 0.03
LANDING_YAW_WITHIN_RAD = 0.1
#: A landed sole lies within this of its surface when Walk takes the next step (rad; 2
#: degrees; 0.015 here). Its swing leg damped by the stance's leg damping as well as by its
#: servo, the ankle lagged and every sole was still 0.13-0.16 rad heel first then.
LANDING_TILT_BELOW_RAD = 0.035
#: The issue's bound on a pushed step, from where Walk moved it (m).
TAKEN_WITHIN_M = 0.05
#: A walking pelvis stays above this (m; the walk lowers it 5 cm, Stand holds 0.91).
PELVIS_ABOVE_M = 0.8
#: The legs' torques change by at most this much per 1 ms step, on average (N m; the
#: chattering servo's was 107, the smooth one's is 1.4).
TORQUE_JUMP_BELOW_NM = 10.0
#: The issue's push while walking: 150 N sideways for 0.1 s (15 N s), one at a random phase
#: and side in every 5 steps (2 in the 10).
PUSH_N = 150.0
PUSH_S = 0.1
PUSH_EVERY_S = 5 * STEP_DURATION_S
#: Sim time after the last step (s): the catch (at least 0.6 s), then Stand.
AFTER_S = 1.5


def failed(trials: dict[int, WalkTrial], ok: Callable[[WalkTrial], bool]) -> list[int]:
    return [seed for seed, trial in trials.items() if not ok(trial)]


def fraction_text(trials: dict[int, WalkTrial], bad: list[int], what: str) -> str:
    return (f'{len(trials) - len(bad)} of {len(trials)} seeds {what}; failed: '
            + ', '.join(f'seed {seed} ({describe(trials[seed])})' for seed in bad))


def describe(trial: WalkTrial) -> str:
    return (f'fell={trial.fell}, {trial.steps} steps, worst landing '
            f'{trial.worst_landing_m:.3f} m, worst tilt '
            f'{max((x.tilt_rad for x in trial.landings), default=0.0):.3f} rad, lowest pelvis '
            f'{trial.lowest_pelvis_m:.3f} m')


def summary(name: str, trials: dict[int, WalkTrial]) -> str:
    """The figures the docs quote, over the seeds (shown with pytest -s)."""
    taken = max(x.taken_error_m for t in trials.values() for x in t.landings)
    return (f'{name}: worst landing {max(t.worst_landing_m for t in trials.values()):.4f} m, '
            f'worst from where Walk took it {taken:.4f} m, '
            f'lowest pelvis {min(t.lowest_pelvis_m for t in trials.values()):.4f} m, ahead '
            f'{min(float(t.pelvis_end[0]) for t in trials.values()):.3f} m, torque jump '
            f'{max(t.leg_torque_jump_nm for t in trials.values()):.2f} N m')


def walked(trial: WalkTrial, steps: int = STEPS) -> bool:
    return not trial.fell and trial.steps == steps and trial.walk_ended_s is not None


@pytest.fixture(scope='module')
def straight() -> dict[int, WalkTrial]:
    plan = straight_steps(STEPS, STRIDE_M)
    duration_s = walk_started_s() + STEPS * STEP_DURATION_S + AFTER_S
    trials = {seed: walk_trial(plan, duration_s, seed=seed) for seed in SEEDS}
    print(summary('straight', trials))
    return trials


def test_eight_of_eight_seeds_walk_six_straight_steps(
        straight: dict[int, WalkTrial]) -> None:
    def ok(trial: WalkTrial) -> bool:
        return (walked(trial) and float(trial.pelvis_end[0]) >= AHEAD_M
                and trial.lowest_pelvis_m > PELVIS_ABOVE_M
                and trial.leg_torque_jump_nm < TORQUE_JUMP_BELOW_NM)
    bad = failed(straight, ok)
    assert len(straight) - len(bad) == 8, fraction_text(straight, bad, 'walked')


def test_eight_of_eight_seeds_land_every_step_within_3_cm(
        straight: dict[int, WalkTrial]) -> None:
    def ok(trial: WalkTrial) -> bool:
        return walked(trial) and all(
            landing.error_m < LANDING_WITHIN_M and landing.yaw_error_rad < LANDING_YAW_WITHIN_RAD
            for landing in trial.landings)
    bad = failed(straight, ok)
    assert len(straight) - len(bad) == 8, fraction_text(straight, bad, 'landed within 3 cm')


def test_eight_of_eight_seeds_land_without_bias(straight: dict[int, WalkTrial]) -> None:
    """On average the feet come down on their steps, not ahead of them (planted, the swing
    servo without the path's acceleration and blind to the pelvis's speed: 2.4 cm ahead)."""
    bad = failed(straight, lambda trial: abs(trial.mean_ahead_m) < LANDING_BIAS_BELOW_M)
    assert len(straight) - len(bad) == 8, fraction_text(straight, bad, 'landed without bias')


def test_eight_of_eight_seeds_land_flat(straight: dict[int, WalkTrial]) -> None:
    """Every sole comes down flat, not heel first (planted, the swinging leg damped by
    LegGains.leg_kd as the stance leg is: 0.13 rad at every landing)."""
    def ok(trial: WalkTrial) -> bool:
        return walked(trial) and all(landing.tilt_rad < LANDING_TILT_BELOW_RAD
                                     for landing in trial.landings)
    bad = failed(straight, ok)
    assert len(straight) - len(bad) == 8, fraction_text(straight, bad, 'landed flat')


def test_the_seeds_perturb_the_walk(straight: dict[int, WalkTrial]) -> None:
    """A seed ignored would make the fractions one run counted eight times."""
    ends = {tuple(round(float(v), 9) for v in trial.pelvis_end) for trial in straight.values()}
    assert len(ends) == len(straight)


@pytest.fixture(scope='module')
def pushed() -> dict[int, WalkTrial]:
    trials = {seed: pushed_walk_trial(seed, PUSHED_STEPS, STRIDE_M, PUSH_N, PUSH_S,
                                      PUSH_EVERY_S, after_s=AFTER_S)[0] for seed in SEEDS}
    print(summary('pushed', trials))
    return trials


def test_pushed_every_five_steps_eight_of_eight_seeds_walk_on(
        pushed: dict[int, WalkTrial]) -> None:
    """Pushed sideways (15 N s) at a random phase of every 5 steps, the walk moves the
    pushed steps (step adjustment), lands each where Walk took it, and walks on."""
    def ok(trial: WalkTrial) -> bool:
        return (walked(trial, PUSHED_STEPS) and float(trial.pelvis_end[0]) >= PUSHED_AHEAD_M
                and trial.lowest_pelvis_m > PELVIS_ABOVE_M
                and all(landing.taken_error_m < TAKEN_WITHIN_M for landing in trial.landings))
    bad = failed(pushed, ok)
    assert len(pushed) - len(bad) == 8, fraction_text(pushed, bad, 'walked on')
    ends = {tuple(round(float(v), 9) for v in trial.pelvis_end) for trial in pushed.values()}
    assert len(ends) == len(pushed)  # the seeds perturb
