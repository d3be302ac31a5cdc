"""Command line of walk_map.py: straight walks over stride x step duration x seed on Dask,
and the map of the fraction of seeds that walk every step (PNG and CSV)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from tutorial_atlas_control.cli.convention import (
    EXIT_INTERRUPTED,
    EXIT_REFUSED,
    add_dask_arguments,
    positive_number,
    print_error,
    whole_number,
)
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.search import (
    WalkMapInputs,
    check_output,
    fastest_walking,
    run_walk_map,
    walk_specs,
    write_map,
)

PROG = 'walk_map.py'


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (its --help is the documentation)."""
    parser = argparse.ArgumentParser(
        prog=PROG, description=(
            'Walk straight offline (walk_trial: the robot standing in the Stand pose, its '
            'start perturbed by each seed) at every stride x step duration, once per seed, in '
            'parallel on Dask distributed, and write where it walks: OUT.csv (per stride and '
            'duration, the fraction of seeds that took every step without a fall), '
            'OUT_runs.csv (every run) and OUT.png (the map). Rows are in input order; the '
            'same inputs give the same map on any number of workers.'))
    parser.add_argument('--strides', type=positive_number, nargs='+', default=[0.25], metavar='M',
                        help='strides (m, at most 0.40; default: 0.25)')
    parser.add_argument('--durations', type=positive_number, nargs='+', default=[0.63], metavar='S',
                        help='step durations (s; default: 0.63)')
    parser.add_argument('--seeds', type=whole_number(1), default=8, metavar='N',
                        help='seeds per cell (default: 8)')
    parser.add_argument('--first-seed', type=whole_number(0), default=0, metavar='K',
                        help='the first seed; seeds K..K+N-1 (default: 0)')
    parser.add_argument('--steps', type=whole_number(1), default=20, metavar='N',
                        help='steps of each walk (default: 20)')
    parser.add_argument('--out', type=Path, default=Path('walk_map'), metavar='OUT',
                        help='prefix: OUT.csv, OUT_runs.csv, OUT.png (default: %(default)s)')
    add_dask_arguments(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """The command line; returns the exit status (1: bad input, nothing written)."""
    args = build_parser().parse_args(argv)
    try:
        inputs = WalkMapInputs(args.strides, args.durations,
                               range(args.first_seed, args.first_seed + args.seeds), args.steps)
        check_output(args.out)
        outcome = run_walk_map(walk_specs(inputs), args.workers, args.scheduler,
                               not args.no_progress)
        if not outcome.rows:
            raise KeyboardInterrupt
        cells, map_path, runs_path, png = write_map(outcome.rows, args.steps, args.out)
    except AtlasControlError as err:
        print_error(PROG, err)
        return EXIT_REFUSED
    except KeyboardInterrupt:  # before any run finished: nothing to keep
        print(f'{PROG}: interrupted before any run finished; nothing written', file=sys.stderr)
        return EXIT_INTERRUPTED
    if outcome.interrupted:
        print(f'{PROG}: interrupted: kept the {len(outcome.rows)} of {outcome.total} runs that '
              f'finished in {map_path}, {runs_path} and {png}', file=sys.stderr)
        return EXIT_INTERRUPTED
    fastest = fastest_walking(cells)
    print(f'walk_map: {len(outcome.rows)} walks, {sum(c.walked for c in cells)} walked '
          f'{args.steps} steps; ' + (
              'no cell where every seed walked' if fastest is None else
              f'fastest where {fastest.seeds} of {fastest.seeds} seeds walk: '
              f'{fastest.stride_m:g} m every {fastest.duration_s:g} s '
              f'({fastest.speed_m_s:.2f} m/s)')
          + f'; map: {map_path}, {png}; runs: {runs_path}')
    return 0
