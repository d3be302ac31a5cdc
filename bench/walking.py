"""The `walking` section: how often pushed and varied walks fall, as fractions of seeds.

Four kinds of run, each perturbed by its seed (walking/start_noise.py), on a pool of
processes: the README's two walks unpushed (20 straight steps sent once, a turn of the 2 m
circle streamed), each landing to be within 3 cm; walk_pushes.py's streamed straight walks
through the AtlasSimInterface, pushed sideways at a random phase in every 5 s; one push at
each of 7 phases of a right and a left step, to either side (walk_trial, an 8-step streamed
walk: the phase pushes); and walk_variations.py's live test sequences. A figure is the
fraction of runs that walked, or that fell.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import walk_pushes
import walk_variations

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'test'))
from support.mode_switching_run import run_mode_switching
from tutorial_atlas_control.balance import Push
from tutorial_atlas_control.walking import (
    STEP_DURATION_S,
    WalkGains,
    circle_steps,
    straight_steps,
)
from tutorial_atlas_control.walking.walk_trial import walk_started_s, walk_trial

#: The pushes' length (s) and period (s), walk_pushes.py's defaults (the issue's 0.1 s).
PUSH_S = 0.1
PUSH_EVERY_S = 5.0
#: The phase pushes: a walk of this many steps, pushed once during one of PHASE_STEPS (4 is
#: the right foot's swing, 5 the left's), at k / PHASES of it, to either side.
PHASE_WALK_STEPS = 8
PHASES = 7
PHASE_STEPS = (4, 5)
#: The variations' stride (m): test_asi_live's.
VARIATION_STRIDE_M = 0.2
#: The README's walks: the straight one's stride (m); the circle's radius (m), steps a turn
#: and feet apart (m); every landing within this of its step (m, rad); sim time after the
#: last step (s: the catch, then Stand).
COURSE_STRIDE_M = 0.25
CIRCLE_RADIUS_M = 2.0
CIRCLE_STEPS_A_TURN = 60
CIRCLE_WIDTH_M = 0.3
LANDING_WITHIN_M = 0.03
LANDING_YAW_WITHIN_RAD = 0.1
AFTER_S = 1.5


@dataclass(frozen=True)
class WalkingBudget:
    """What the section runs: pushed walks (seeds, steps, forces in N), phase pushes (the
    steps pushed, phases of each, (force N, step adjustment on) cases), variations (seeds),
    the README's walks (seeds, the straight walk's steps, the circle's steps)."""

    push_seeds: int
    push_steps: int
    push_forces_n: tuple[float, ...]
    phase_steps: tuple[int, ...]
    phases: int
    phase_cases: tuple[tuple[float, bool], ...]
    variation_seeds: int
    course_seeds: int
    straight_steps: int
    circle_steps: int
    mode_switching_seeds: int


BUDGETS = {
    'quick': WalkingBudget(1, 4, (150.0,), (4,), 1, ((150.0, True),), 1, 1, 4, 4, 1),
    'default': WalkingBudget(8, 60, (150.0, 175.0), PHASE_STEPS, PHASES, ((150.0, True),), 8,
                             8, 20, CIRCLE_STEPS_A_TURN, 8),
    'full': WalkingBudget(8, 60, (150.0, 175.0, 200.0), PHASE_STEPS, PHASES,
                          ((150.0, True), (150.0, False), (200.0, True), (250.0, True)), 8,
                          8, 20, CIRCLE_STEPS_A_TURN, 8),
}


def fell_fraction(fell: Sequence[bool]) -> float:
    """The share of runs that fell."""
    if not fell:
        raise ValueError('no runs')
    return sum(bool(f) for f in fell) / len(fell)


def force_key(prefix: str, force_n: float, adjust: bool = True) -> str:
    """`PREFIX_fell_fraction_150n` (`_unadjusted` without step adjustment)."""
    return f'{prefix}_fell_fraction_{force_n:g}n' + ('' if adjust else '_unadjusted')


@dataclass(frozen=True)
class PhasePush:
    """One phase push: during `step`, at `phase` of it, towards `side` (+1 left)."""

    index: int
    step: int
    phase: float
    side: float
    force_n: float
    adjust: bool


def phase_pushes(steps: Sequence[int], phases: int, force_n: float,
                 adjust: bool) -> list[PhasePush]:
    """Every step x phase x side, indexed (the index is the run's seed)."""
    return [PhasePush(index, step, phase, side, force_n, adjust)
            for index, (step, phase, side) in enumerate(
                (step, k / phases, side) for step in steps for k in range(phases)
                for side in (1.0, -1.0))]


def phase_push_fell(case: PhasePush) -> bool:
    """An 8-step streamed walk from a start perturbed by the case's index, pushed once."""
    gains = WalkGains(adjust_steps=case.adjust)
    start = walk_started_s(gains) + (case.step - 1 + case.phase) * STEP_DURATION_S
    push = Push(start, (0.0, case.side * case.force_n, 0.0), PUSH_S)
    duration_s = walk_started_s(gains) + PHASE_WALK_STEPS * STEP_DURATION_S + 1.5
    trial = walk_trial(straight_steps(PHASE_WALK_STEPS, 0.25), duration_s, gains,
                       streaming=True, pushes=[push], seed=case.index)
    return trial.fell


def course_walk(job: tuple[str, int, int]) -> tuple[bool, float]:
    """One of the README's walks, ('straight' or 'circle', steps, seed): whether it walked
    every step, caught itself and landed each within LANDING_WITHIN_M and
    LANDING_YAW_WITHIN_RAD of its step; and its worst landing (m)."""
    kind, steps, seed = job
    if kind == 'straight':
        plan, streaming = straight_steps(steps, COURSE_STRIDE_M), False
    else:
        plan = circle_steps(CIRCLE_RADIUS_M, CIRCLE_STEPS_A_TURN, 1,
                            width_m=CIRCLE_WIDTH_M)[:steps]
        streaming = True
    duration_s = walk_started_s() + len(plan) * plan[0].duration_s + AFTER_S
    trial = walk_trial(plan, duration_s, streaming=streaming, seed=seed)
    within = (not trial.fell and trial.steps == steps and trial.walk_ended_s is not None
              and all(landing.error_m < LANDING_WITHIN_M
                      and landing.yaw_error_rad < LANDING_YAW_WITHIN_RAD
                      for landing in trial.landings))
    return within, trial.worst_landing_m


def mode_switching_fell(seed: int) -> bool:
    """DRCSim's mode-switching demo offline from the default start perturbed by `seed`."""
    return run_mode_switching(seed).fell_at_s is not None


def _pushed_fell(job: tuple[int, int, float]) -> bool:
    seed, steps, force_n = job
    return walk_pushes.run(seed, steps, force_n, PUSH_S, PUSH_EVERY_S).fell


def _varied_fell(seed: int) -> bool:
    return walk_variations.run(seed, VARIATION_STRIDE_M).fell_in is not None


def walking_figures(budget: WalkingBudget, workers: int = 2,
                    log: Callable[[str], None] = print,
                    pool_map: Callable[[Callable, Iterable], Iterable] | None = None
                    ) -> dict[str, float]:
    """The section's figures: the fraction of the README's walks (seeds 0..) that walked
    within 3 cm and their worst landing; the fraction of mode-switching demos that fell
    (seeds 0..); per force, the fraction of pushed walks (seeds 0..) and of phase pushes
    that fell; the fraction of variations (seeds 1..) that fell; the runs."""
    with ProcessPoolExecutor(workers) as pool:
        run = pool_map or pool.map
        figures: dict[str, float] = {}
        for kind, steps in (('straight', budget.straight_steps),
                            ('circle', budget.circle_steps)):
            walks = list(run(course_walk, [(kind, steps, seed)
                                           for seed in range(budget.course_seeds)]))
            within = sum(ok for ok, _ in walks)
            worst = max(landing for _, landing in walks)
            figures.update({f'walk_{kind}_runs': float(len(walks)),
                            f'walk_{kind}_within_fraction': within / len(walks),
                            f'walk_{kind}_worst_landing_m': worst})
            log(f'walking: {kind}, {steps} steps: {within} of {len(walks)} seeds walked '
                f'within {LANDING_WITHIN_M * 100:g} cm (worst landing {worst * 100:.1f} cm)')
        fell = list(run(mode_switching_fell, range(budget.mode_switching_seeds)))
        figures.update({'mode_switching_runs': float(len(fell)),
                        'mode_switching_fell_fraction': fell_fraction(fell)})
        log(f'walking: DRCSim\'s mode-switching demo: {sum(fell)} of {len(fell)} seeds fell')
        figures['walk_pushes_runs'] = float(budget.push_seeds)
        for force in budget.push_forces_n:
            fell = list(run(_pushed_fell, [(seed, budget.push_steps, force)
                                           for seed in range(budget.push_seeds)]))
            figures[force_key('walk_pushes', force)] = fell_fraction(fell)
            log(f'walking: {force:g} N every {PUSH_EVERY_S:g} s of {budget.push_steps} steps: '
                f'{sum(fell)} of {len(fell)} seeds fell')
        for force, adjust in budget.phase_cases:
            cases = phase_pushes(budget.phase_steps, budget.phases, force, adjust)
            fell = list(run(phase_push_fell, cases))
            figures[force_key('walk_phase_pushes', force, adjust)] = fell_fraction(fell)
            figures['walk_phase_pushes_runs'] = float(len(cases))
            log(f'walking: one {force:g} N push at {len(cases)} phases'
                + ('' if adjust else ' (no step adjustment)') + f': {sum(fell)} fell')
        seeds = range(1, budget.variation_seeds + 1)
        fell = list(run(_varied_fell, seeds))
        figures['walk_variations_fell_fraction'] = fell_fraction(fell)
        figures['walk_variations_runs'] = float(len(fell))
        log(f'walking: test_asi_live\'s walks varied: {sum(fell)} of {len(fell)} seeds fell')
    return figures
