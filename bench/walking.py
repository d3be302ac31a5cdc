"""The `walking` section: how often pushed and varied walks fall, as fractions of seeds.

Three kinds of run, each perturbed by its seed (walking/start_noise.py), on a pool of
processes: walk_pushes.py's streamed straight walks through the AtlasSimInterface, pushed
sideways at a random phase in every 5 s; one push at each of 7 phases of a right and a
left step, to either side (walk_trial, an 8-step streamed walk: the phase pushes); and
walk_variations.py's live test sequences. A figure is the fraction of runs that fell.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import walk_pushes
import walk_variations

from tutorial_atlas_control.balance import Push
from tutorial_atlas_control.walking import STEP_DURATION_S, WalkGains, straight_steps
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


@dataclass(frozen=True)
class WalkingBudget:
    """What the section runs: pushed walks (seeds, steps, forces in N), phase pushes (the
    steps pushed, phases of each, (force N, step adjustment on) cases), variations (seeds)."""

    push_seeds: int
    push_steps: int
    push_forces_n: tuple[float, ...]
    phase_steps: tuple[int, ...]
    phases: int
    phase_cases: tuple[tuple[float, bool], ...]
    variation_seeds: int


BUDGETS = {
    'quick': WalkingBudget(1, 4, (150.0,), (4,), 1, ((150.0, True),), 1),
    'default': WalkingBudget(8, 60, (150.0, 175.0), PHASE_STEPS, PHASES, ((150.0, True),), 8),
    'full': WalkingBudget(8, 60, (150.0, 175.0, 200.0), PHASE_STEPS, PHASES,
                          ((150.0, True), (150.0, False), (200.0, True), (250.0, True)), 8),
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


def _pushed_fell(job: tuple[int, int, float]) -> bool:
    seed, steps, force_n = job
    return walk_pushes.run(seed, steps, force_n, PUSH_S, PUSH_EVERY_S).fell


def _varied_fell(seed: int) -> bool:
    return walk_variations.run(seed, VARIATION_STRIDE_M).fell_in is not None


def walking_figures(budget: WalkingBudget, workers: int = 2,
                    log: Callable[[str], None] = print,
                    pool_map: Callable[[Callable, Iterable], Iterable] | None = None
                    ) -> dict[str, float]:
    """The section's figures: per force, the fraction of pushed walks (seeds 0..) and of
    phase pushes that fell; the fraction of variations (seeds 1..) that fell; the runs."""
    with ProcessPoolExecutor(workers) as pool:
        run = pool_map or pool.map
        figures: dict[str, float] = {'walk_pushes_runs': float(budget.push_seeds)}
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
