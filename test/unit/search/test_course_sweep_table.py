"""The course sweep's arithmetic on synthetic rows (search/course_sweep.py): the runs in
order, one line per variant (through, gates, falls, the median clock of the runs through,
the closest calls over all runs) and its Markdown; the refusals. The walks themselves:
test/integration/test_course_sweep.py."""

from __future__ import annotations

import pytest

from tutorial_atlas_control.course import CourseError
from tutorial_atlas_control.search import SweepError
from tutorial_atlas_control.search.course_sweep import (
    course_specs,
    variant_lines,
    variant_table,
)


def row(variant: str, seed: int, completion: int, fell_at_s: float | None, clock_s: float,
        lowest: float, widest: float) -> dict:
    return {'index': 0, 'variant': variant, 'seed': seed, 'world': 'vrc_task_2',
            'to_gate': 'gate_4', 'through': completion == 4 and fell_at_s is None,
            'completion': completion, 'scorer_falls': 0 if fell_at_s is None else 1,
            'fell_at_s': fell_at_s, 'course_clock_s': clock_s, 'lowest_pelvis_m': lowest,
            'lowest_leg': f'gate_{seed}', 'widest_capture_m': widest,
            'widest_leg': f'gate_{4 - seed}'}


ROWS = [row('qualification', 1, 4, None, 300.0, 0.80, 0.12),
        row('qualification', 2, 4, None, 320.0, 0.78, 0.20),
        row('qualification', 3, 1, 107.0, 85.0, 0.45, 0.75),
        row('finals_rubble', 1, 4, None, 400.0, 0.82, 0.10)]


def test_one_line_per_variant_over_its_seeds() -> None:
    qualification, rubble = variant_lines(ROWS)
    assert (qualification.variant, qualification.runs, qualification.through) == \
        ('qualification', 3, 2)
    assert qualification.completions == (4, 4, 1)
    assert (qualification.scorer_falls, qualification.fell) == (1, 1)
    assert qualification.median_clock_s == 310.0  # of the runs through only
    assert (qualification.lowest_pelvis_m, qualification.lowest_leg) == (0.45, 'gate_3')
    assert (qualification.widest_capture_m, qualification.widest_leg) == (0.75, 'gate_1')
    assert (rubble.through, rubble.median_clock_s) == (1, 400.0)


def test_the_table_compares_the_clock_with_a_person() -> None:
    table = variant_table(variant_lines(ROWS), 'gate_4').splitlines()
    assert table[0].startswith('| variant | through to gate_4 | gates passed per run |')
    assert table[2] == ('| qualification | 2 of 3 | 4 4 1 | 1 | 1 | 310 s (6.7x a person) '
                        '| 0.45 m (gate_3) | 0.75 m (gate_1) |')
    assert len(table) == 4


def test_nothing_through_has_no_clock() -> None:
    (line,) = variant_lines([row('qualification', 3, 1, 107.0, 85.0, 0.45, 0.75)])
    assert line.median_clock_s is None
    assert '| 0 of 1 | 1 | 1 | 1 |  |' in variant_table([line], 'gate_4')


def test_specs_are_variant_major_and_refused_in_one_line() -> None:
    specs = course_specs(['qualification', 'finals_rubble'], [1, None])
    assert [(s.index, s.variant, s.seed) for s in specs] == [
        (0, 'qualification', 1), (1, 'qualification', None), (2, 'finals_rubble', 1),
        (3, 'finals_rubble', None)]
    assert specs[0].to_gate == 'gate_4' and specs[0].world == 'vrc_task_2'
    with pytest.raises(SweepError, match='needs a variant and a seed'):
        course_specs([], [1])
    with pytest.raises(CourseError, match="unknown course variant 'mud'"):
        course_specs(['mud'], [1])
    with pytest.raises(SweepError, match="unknown gate 'gate_9'"):
        course_specs(['qualification'], [1], to_gate='gate_9')
