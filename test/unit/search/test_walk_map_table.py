"""The walk map's arithmetic on synthetic rows (search/walk_map.py): cells gathered per
stride x duration, their fractions and failed seeds, the fastest cell every seed walked,
the CSV and the PNG; the grid's order and its refusals. The walks themselves:
test/integration/test_walk_map.py."""

from __future__ import annotations

from pathlib import Path

import pytest

from tutorial_atlas_control.search import SweepError
from tutorial_atlas_control.search.walk_map import (
    WalkMapInputs,
    fastest_walking,
    map_cells,
    map_csv,
    walk_specs,
    write_map,
)


def row(stride: float, duration: float, seed: int, walked: bool, worst: float = 0.02) -> dict:
    return {'index': 0, 'stride_m': stride, 'duration_s': duration, 'seed': seed, 'steps': 20,
            'walked': walked, 'fell': not walked, 'steps_taken': 20 if walked else 3,
            'worst_landing_m': worst}


#: 0.4 m / 0.5 s (0.8 m/s): 1 of 2; 0.3 m / 0.5 s (0.6 m/s): 2 of 2; 0.3 m / 0.6 s: 2 of 2.
ROWS = [row(0.3, 0.5, 0, True, 0.021), row(0.3, 0.5, 1, True, 0.034),
        row(0.3, 0.6, 0, True), row(0.3, 0.6, 1, True),
        row(0.4, 0.5, 0, True), row(0.4, 0.5, 1, False, 0.2)]


def test_cells_are_fractions_of_seeds_with_the_failed_ones_named() -> None:
    cells = map_cells(ROWS)
    assert [(c.stride_m, c.duration_s, c.walked, c.seeds) for c in cells] == [
        (0.3, 0.5, 2, 2), (0.3, 0.6, 2, 2), (0.4, 0.5, 1, 2)]
    assert cells[2].fraction == 0.5 and cells[2].failed_seeds == (1,)
    assert cells[0].worst_landing_m == 0.034  # over the seeds that walked only
    assert cells[2].worst_landing_m == 0.02


def test_the_fastest_cell_is_the_fastest_where_every_seed_walked() -> None:
    fastest = fastest_walking(map_cells(ROWS))
    assert fastest is not None
    assert (fastest.stride_m, fastest.duration_s) == (0.3, 0.5)  # not 0.4 m: 1 of 2
    assert fastest.speed_m_s == pytest.approx(0.6)
    assert fastest_walking(map_cells([row(0.3, 0.5, 0, False)])) is None
    # Equal speeds: the longer stride.
    tie = map_cells([row(0.2, 0.4, 0, True), row(0.3, 0.6, 0, True)])
    assert fastest_walking(tie).stride_m == 0.3


def test_the_map_csv_and_png(tmp_path: Path) -> None:
    cells, map_path, runs_path, png = write_map(ROWS, 20, tmp_path / 'map')
    assert map_csv(cells) == map_path.read_text()
    assert map_path.read_text().splitlines() == [
        'stride_m,duration_s,speed_m_s,seeds,walked,fraction,failed_seeds,worst_landing_m',
        '0.3,0.5,0.600,2,2,1.000,,0.0340',
        '0.3,0.6,0.500,2,2,1.000,,0.0200',
        '0.4,0.5,0.800,2,1,0.500,1,0.0200']
    assert len(runs_path.read_text().splitlines()) == 1 + len(ROWS)
    assert png.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    assert sorted(p.name for p in tmp_path.iterdir()) == ['map.csv', 'map.png', 'map_runs.csv']


def test_the_grid_is_stride_then_duration_then_seed() -> None:
    specs = walk_specs(WalkMapInputs((0.2, 0.3), (0.5,), range(3, 5), steps=4))
    assert [(s.index, s.stride_m, s.duration_s, s.seed, s.steps) for s in specs] == [
        (0, 0.2, 0.5, 3, 4), (1, 0.2, 0.5, 4, 4), (2, 0.3, 0.5, 3, 4), (3, 0.3, 0.5, 4, 4)]


@pytest.mark.parametrize(('strides', 'durations', 'seeds', 'message'), [
    ((0.5,), (0.5,), (0,), 'strides must be in (0, 0.40] m'),
    ((0.3,), (0.0,), (0,), 'step durations must be in (0, 5] s'),
    ((), (0.5,), (0,), 'a walk map needs'),
])
def test_a_grid_outside_what_walk_takes_is_refused(strides: tuple, durations: tuple,
                                                   seeds: tuple, message: str) -> None:
    with pytest.raises(SweepError, match=message.replace('(', r'\(').replace(')', r'\)')
                       .replace('[', r'\[').replace(']', r'\]')):
        WalkMapInputs(strides, durations, seeds)
