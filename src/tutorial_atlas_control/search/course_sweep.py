"""The course walked over its variants x seeds on Dask, and the table of how far each got.

A run is offline/course_route.py's course walk: the course walker's legs from a world's start
to a gate, on one of the course's variants (course/variants.py: the qualification's world or
one of the VRC finals' changes), its start perturbed by a seed. Runs are tasks of sweep.py's
engine (a local cluster, or any scheduler by address); rows come back in input order, so the
table does not depend on the number of workers. A variant's line says over its seeds how
many passed every gate to the last asked without a fall, the gates passed, the falls, the
course clock (sim time from gate_0 to the last gate passed), and where a leg came closest to
a fall: the lowest pelvis over the ground and the widest capture point from the nearer sole.
"""

from __future__ import annotations

import itertools
import statistics
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

from tutorial_atlas_control.course import GATES, course_variant, world_start
from tutorial_atlas_control.offline import course_walk
from tutorial_atlas_control.search.runs import SweepError
from tutorial_atlas_control.search.sweep import SweepEngine, SweepOutcome

__all__ = ['COURSE_COLUMNS', 'CourseSpec', 'VariantLine', 'course_specs', 'run_course',
           'run_course_sweep', 'variant_lines', 'variant_table']

#: A run's row's columns, in the CSV's and JSON's order.
COURSE_COLUMNS = ('index', 'variant', 'seed', 'world', 'to_gate', 'through', 'completion',
                  'scorer_falls', 'fell_at_s', 'course_clock_s', 'steps_taken', 'pelvis_x_m',
                  'pelvis_y_m', 'lowest_pelvis_m', 'lowest_leg', 'widest_capture_m',
                  'widest_leg', 'cpu_s')
#: A person walking the course's ~60 m at about 1.3 m/s (s): the issue's yardstick.
PERSON_COURSE_S = 60.0 / 1.3


@dataclass(frozen=True)
class CourseSpec:
    """One run's inputs: the course walked on `variant` from `world`'s start to `to_gate`,
    the start perturbed by `seed` (None: not)."""

    index: int
    variant: str
    seed: int | None
    world: str
    to_gate: str


def course_specs(variants: Sequence[str], seeds: Sequence[int | None], world: str = 'vrc_task_2',
                 to_gate: str = GATES[-1].name) -> list[CourseSpec]:
    """Every run, variant-major, then seed.

    Raises:
        SweepError: nothing to run.
        CourseError: an unknown variant, world or gate.
    """
    if not variants or not seeds:
        raise SweepError('a course sweep needs a variant and a seed')
    for name in variants:
        course_variant(name)
    world_start(world)
    if to_gate not in {gate.name for gate in GATES}:
        raise SweepError(f'unknown gate {to_gate!r}; known: '
                         + ', '.join(gate.name for gate in GATES))
    return [CourseSpec(index, variant, seed, world, to_gate)
            for index, (variant, seed) in enumerate(itertools.product(variants, seeds))]


def run_course(spec: CourseSpec) -> dict[str, Any]:
    """One course walk and its row (`through`: every leg walked, no fall)."""
    walk = course_walk(spec.seed, to_gate=spec.to_gate, world_name=spec.world,
                       variant=course_variant(spec.variant))
    lowest = min(walk.legs, key=lambda leg: leg.lowest_pelvis_m, default=None)
    widest = max(walk.legs, key=lambda leg: leg.widest_capture_m, default=None)
    row = {**asdict(spec), 'through': walk.outcome == 'walked' and walk.fell_at_s is None,
            'completion': walk.completion, 'scorer_falls': walk.scorer_falls,
            'fell_at_s': walk.fell_at_s, 'course_clock_s': round(walk.course_clock_s, 3),
            'steps_taken': walk.steps_taken, 'pelvis_x_m': round(walk.pelvis_xy[0], 3),
            'pelvis_y_m': round(walk.pelvis_xy[1], 3),
            'lowest_pelvis_m': None if lowest is None else lowest.lowest_pelvis_m,
            'lowest_leg': None if lowest is None else lowest.gate,
            'widest_capture_m': None if widest is None else widest.widest_capture_m,
            'widest_leg': None if widest is None else widest.gate,
            'cpu_s': round(walk.cpu_s, 1)}
    return {column: row[column] for column in COURSE_COLUMNS}


def run_course_sweep(specs: Sequence[CourseSpec], workers: int | None = None,
                     scheduler: str | None = None, progress: bool = True) -> SweepOutcome:
    """Every spec as a Dask task (SweepEngine), rows in input order."""
    with SweepEngine(workers, scheduler) as engine:
        return engine.run(specs, progress, run=run_course)


@dataclass(frozen=True)
class VariantLine:
    """A variant over its seeds: runs through, gates (completion) per run, falls (the
    scorer's, summed; and runs our fall criterion ended), the median course clock of the
    runs through, and the closest call over them all."""

    variant: str
    runs: int
    through: int
    completions: tuple[int, ...]
    scorer_falls: int
    fell: int
    median_clock_s: float | None
    lowest_pelvis_m: float | None
    lowest_leg: str | None
    widest_capture_m: float | None
    widest_leg: str | None


def variant_lines(rows: Sequence[dict[str, Any]]) -> list[VariantLine]:
    """One line per variant, in the rows' order."""
    lines = []
    for variant, group in itertools.groupby(rows, key=lambda row: row['variant']):
        runs = list(group)
        through = [row for row in runs if row['through']]
        lows = [row for row in runs if row['lowest_pelvis_m'] is not None]
        wides = [row for row in runs if row['widest_capture_m'] is not None]
        low = min(lows, key=lambda row: row['lowest_pelvis_m'], default=None)
        wide = max(wides, key=lambda row: row['widest_capture_m'], default=None)
        lines.append(VariantLine(
            variant, len(runs), len(through), tuple(row['completion'] for row in runs),
            sum(row['scorer_falls'] for row in runs),
            sum(row['fell_at_s'] is not None for row in runs),
            statistics.median(row['course_clock_s'] for row in through) if through else None,
            None if low is None else low['lowest_pelvis_m'],
            None if low is None else low['lowest_leg'],
            None if wide is None else wide['widest_capture_m'],
            None if wide is None else wide['widest_leg']))
    return lines


def _figure(value: float | None, unit: str, leg: str | None) -> str:
    return '' if value is None else f'{value:.2f} {unit} ({leg})'


def variant_table(lines: Sequence[VariantLine], to_gate: str) -> str:
    """The lines as a Markdown table (the README's)."""
    head = ('| variant | through to ' + to_gate + ' | gates passed per run | scorer falls '
            '| runs fallen | median course clock | lowest pelvis | widest capture point |\n'
            '| --- | --- | --- | --- | --- | --- | --- | --- |\n')
    body = ''.join(
        f'| {line.variant} | {line.through} of {line.runs} | '
        f'{" ".join(str(c) for c in line.completions)} | {line.scorer_falls} | {line.fell} | '
        + ('' if line.median_clock_s is None else
           f'{line.median_clock_s:.0f} s ({line.median_clock_s / PERSON_COURSE_S:.1f}x a '
           'person)')
        + f' | {_figure(line.lowest_pelvis_m, "m", line.lowest_leg)} | '
        f'{_figure(line.widest_capture_m, "m", line.widest_leg)} |\n'
        for line in lines)
    return head + body
