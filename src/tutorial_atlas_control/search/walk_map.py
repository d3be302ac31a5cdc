"""Where it walks: straight walks over stride x step duration x seed on Dask, and the map of
the fraction of seeds that walk every step at each stride and duration.

One deterministic walk per cell would draw a chaotic border: a cell is judged over seeds,
each perturbing the walk's start (walking/start_noise.py). Runs are tasks of sweep.py's
engine (a local cluster, or any scheduler by address); rows come back in input order, so
the map does not depend on the number of workers.
"""

from __future__ import annotations

import csv
import io
import itertools
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from tutorial_atlas_control.search.runs import SweepError
from tutorial_atlas_control.search.sweep import SweepEngine, SweepOutcome, atomic_write
from tutorial_atlas_control.walking import straight_walk_trial

__all__ = ['MapCell', 'WalkMapInputs', 'WalkSpec', 'fastest_walking', 'map_cells',
           'map_csv', 'plot_map', 'run_walk', 'run_walk_map', 'walk_specs', 'write_map']

#: Sim time (s) after the last step: the catch and a moment of Stand.
AFTER_WALK_S = 2.0


@dataclass(frozen=True)
class WalkMapInputs:
    """The grid: every stride (m) x step duration (s) x seed, each a walk of `steps`."""

    strides_m: Sequence[float]
    durations_s: Sequence[float]
    seeds: Sequence[int]
    steps: int = 20

    def __post_init__(self) -> None:
        if not (self.strides_m and self.durations_s and self.seeds) or self.steps < 1:
            raise SweepError('a walk map needs a stride, a duration, a seed and a step')
        if any(not 0.0 < s <= 0.40 for s in self.strides_m):
            raise SweepError('strides must be in (0, 0.40] m (Walk clamps longer ones)')
        if any(not 0.0 < d <= 5.0 for d in self.durations_s):
            raise SweepError('step durations must be in (0, 5] s')


@dataclass(frozen=True)
class WalkSpec:
    """One run's inputs: a straight walk of `steps` steps of `stride_m` at `duration_s`."""

    index: int
    stride_m: float
    duration_s: float
    seed: int
    steps: int


def walk_specs(inputs: WalkMapInputs) -> list[WalkSpec]:
    """Every run, stride-major, then duration, then seed."""
    grid = itertools.product(inputs.strides_m, inputs.durations_s, inputs.seeds)
    return [WalkSpec(index, stride, duration, seed, inputs.steps)
            for index, (stride, duration, seed) in enumerate(grid)]


def run_walk(spec: WalkSpec) -> dict[str, Any]:
    """One walk (walk_trial, its start perturbed by the spec's seed) and its row:
    `walked` = every step taken without a fall."""
    trial = straight_walk_trial(spec.steps, spec.stride_m, spec.duration_s, spec.seed,
                                AFTER_WALK_S)
    return {**asdict(spec), 'walked': not trial.fell and trial.steps == spec.steps,
            'fell': trial.fell, 'steps_taken': trial.steps,
            'worst_landing_m': round(trial.worst_landing_m, 6)}


def run_walk_map(specs: Sequence[WalkSpec], workers: int | None = None,
                 scheduler: str | None = None, progress: bool = True) -> SweepOutcome:
    """Every spec as a Dask task (SweepEngine), rows in input order."""
    with SweepEngine(workers, scheduler) as engine:
        return engine.run(specs, progress, run=run_walk)


@dataclass(frozen=True)
class MapCell:
    """A stride x duration: how many of its seeds walked, and the worst landing of those."""

    stride_m: float
    duration_s: float
    seeds: int
    walked: int
    failed_seeds: tuple[int, ...]
    worst_landing_m: float | None

    @property
    def fraction(self) -> float:
        return self.walked / self.seeds

    @property
    def speed_m_s(self) -> float:
        return self.stride_m / self.duration_s


def map_cells(rows: Sequence[dict[str, Any]]) -> list[MapCell]:
    """The runs' rows gathered per stride x duration, in the rows' order."""
    cells: dict[tuple[float, float], list[dict[str, Any]]] = {}
    for row in rows:
        cells.setdefault((row['stride_m'], row['duration_s']), []).append(row)
    result = []
    for (stride, duration), runs in cells.items():
        walked = [run for run in runs if run['walked']]
        result.append(MapCell(stride, duration, len(runs), len(walked),
                              tuple(run['seed'] for run in runs if not run['walked']),
                              max((run['worst_landing_m'] for run in walked), default=None)))
    return result


def fastest_walking(cells: Sequence[MapCell]) -> MapCell | None:
    """The fastest cell (stride / duration; the longer stride first among equals) where every
    seed walked; None if there is none."""
    every = [cell for cell in cells if cell.walked == cell.seeds]
    return max(every, key=lambda cell: (round(cell.speed_m_s, 9), cell.stride_m), default=None)


MAP_COLUMNS = ('stride_m', 'duration_s', 'speed_m_s', 'seeds', 'walked', 'fraction',
               'failed_seeds', 'worst_landing_m')


def map_csv(cells: Sequence[MapCell]) -> str:
    """The map as CSV text (MAP_COLUMNS; failed seeds space-separated)."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator='\n')
    writer.writerow(MAP_COLUMNS)
    for cell in cells:
        writer.writerow([f'{cell.stride_m:g}', f'{cell.duration_s:g}', f'{cell.speed_m_s:.3f}',
                         cell.seeds, cell.walked, f'{cell.fraction:.3f}',
                         ' '.join(str(seed) for seed in cell.failed_seeds),
                         '' if cell.worst_landing_m is None else f'{cell.worst_landing_m:.4f}'])
    return out.getvalue()


def plot_map(cells: Sequence[MapCell], steps: int, path: Path) -> Path:
    """The fraction of seeds that walked, stride by duration, each cell labelled `k/n`;
    the fastest cell every seed walked outlined."""
    import matplotlib  # noqa: PLC0415 - only the plot needs it
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt  # noqa: PLC0415
    import numpy as np  # noqa: PLC0415

    strides = sorted({cell.stride_m for cell in cells})
    durations = sorted({cell.duration_s for cell in cells})
    grid = np.full((len(strides), len(durations)), np.nan)
    figure, axes = plt.subplots(figsize=(1.1 * len(durations) + 2.5, 0.8 * len(strides) + 1.8))
    for cell in cells:
        i, j = strides.index(cell.stride_m), durations.index(cell.duration_s)
        grid[i, j] = cell.fraction
        axes.text(j, i, f'{cell.walked}/{cell.seeds}', ha='center', va='center', fontsize=9)
    image = axes.imshow(grid, origin='lower', cmap='RdYlGn', vmin=0.0, vmax=1.0, aspect='auto')
    fastest = fastest_walking(cells)
    if fastest is not None:
        i, j = strides.index(fastest.stride_m), durations.index(fastest.duration_s)
        axes.add_patch(plt.Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, lw=2.5,
                                     edgecolor='black'))
    axes.set_xticks(range(len(durations)), [f'{d:g}' for d in durations])
    axes.set_yticks(range(len(strides)), [f'{s:g}' for s in strides])
    axes.set_xlabel('step duration (s)')
    axes.set_ylabel('stride (m)')
    title = f'seeds that walk {steps} straight steps'
    if fastest is not None:
        title += (f'\nfastest where all walk (outlined): {fastest.stride_m:g} m / '
                  f'{fastest.duration_s:g} s = {fastest.speed_m_s:.2f} m/s')
    axes.set_title(title, fontsize=10)
    figure.colorbar(image, ax=axes, label='fraction of seeds')
    figure.tight_layout()
    partial = path.with_name(f'.{path.stem}.partial.png')
    try:
        figure.savefig(partial, dpi=100)
        partial.replace(path)
    except OSError as err:
        raise SweepError(f'cannot write {path}: {err.strerror or err}') from err
    finally:
        plt.close(figure)
        partial.unlink(missing_ok=True)
    return path


def write_map(rows: Sequence[dict[str, Any]], steps: int, prefix: Path
              ) -> tuple[list[MapCell], Path, Path, Path]:
    """PREFIX.csv (the map), PREFIX_runs.csv (every run) and PREFIX.png; the cells."""
    cells = map_cells(rows)
    paths = (prefix.with_name(prefix.name + '.csv'), prefix.with_name(prefix.name + '_runs.csv'))
    atomic_write(paths[0], map_csv(cells))
    columns = list(rows[0]) if rows else []
    out = io.StringIO()
    writer = csv.DictWriter(out, columns, lineterminator='\n')
    writer.writeheader()
    writer.writerows(rows)
    atomic_write(paths[1], out.getvalue())
    png = plot_map(cells, steps, prefix.with_name(prefix.name + '.png'))
    return cells, paths[0], paths[1], png
