"""Command line of sweep.py: many offline runs on Dask, one table (CSV and JSON)."""

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
    SweepError,
    SweepInputs,
    build_specs,
    check_output,
    parse_latency,
    parse_push,
    run_sweep,
    write_table,
)
from tutorial_atlas_control.sim import DEFAULT_GAINS_FILE

PROG = 'sweep.py'


def _trajectory(text: str) -> tuple[str, str]:
    file, sep, name = text.rpartition(':')
    if not sep or not file or not name:
        raise argparse.ArgumentTypeError(f'{text!r} is not FILE:NAME')
    return file, name


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (its --help is the documentation)."""
    parser = argparse.ArgumentParser(
        prog=PROG, description=(
            'Play every combination of trajectories, gains, gain scales, timing scales and '
            'pushes offline (as run_offline.py), in parallel on Dask distributed, and write '
            'one table, OUT.csv and OUT.json: fell, fall time, pelvis and feet displacement, '
            'tracking RMS, seed. Rows are in input order; the same inputs give the same table '
            'on any number of workers. Ctrl-C keeps the finished rows.'))
    parser.add_argument('trajectory_file', metavar='YAML_FILE', help='trajectory file')
    parser.add_argument('names', metavar='NAME', nargs='+', help='trajectory names in YAML_FILE')
    parser.add_argument('--trajectory', type=_trajectory, action='append', default=[],
                        metavar='FILE:NAME', help='one more trajectory (repeatable)')
    parser.add_argument('--gains', action='append', metavar='FILE',
                        help='gains YAML (repeatable; default: config/atlas_controller.yaml)')
    parser.add_argument('--gain-scale', type=positive_number, nargs='+', default=[1.0], metavar='X',
                        help='factors on every p, i, d (default: 1)')
    parser.add_argument('--time-scale', type=positive_number, nargs='+', default=[1.0], metavar='X',
                        help='factors on every waypoint duration (default: 1)')
    parser.add_argument('--push', action='append', metavar='AT_S:FX,FY,FZ:DURATION_S',
                        help='a world-frame force (N) on the pelvis, AT_S s after the first '
                             'command (repeatable: one row each; "none" for a row without)')
    parser.add_argument('--latency-ms', metavar='LO:HI',
                        help='delay each command by LO..HI ms (1 ms steps, drawn from the row\'s '
                             'seed) as live delivery does (default: none: at once)')
    parser.add_argument('--repeat', type=whole_number(1), default=1, metavar='N',
                        help='play each combination N times, seeds apart (with --latency-ms: '
                             'N draws of the latency; default: 1)')
    parser.add_argument('--settle', type=float, default=3.0, metavar='S',
                        help='sim time after the last waypoint (default: %(default)g)')
    parser.add_argument('--seed', type=int, default=0,
                        help='first row\'s seed; row k has SEED + k (default: 0)')
    parser.add_argument('--out', type=Path, default=Path('sweep'), metavar='OUT',
                        help='table prefix: OUT.csv and OUT.json (default: %(default)s)')
    add_dask_arguments(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """The command line; returns the exit status (1: bad input, nothing written)."""
    args = build_parser().parse_args(argv)
    try:
        pushes = [None if text == 'none' else parse_push(text) for text in args.push or ['none']]
        latency = parse_latency(args.latency_ms) if args.latency_ms else (0, 0)
        inputs = SweepInputs(
            [(args.trajectory_file, name) for name in args.names] + args.trajectory,
            args.gains or [str(DEFAULT_GAINS_FILE)], args.gain_scale, args.time_scale,
            pushes, args.settle, args.seed, latency, args.repeat)
        check_output(args.out)
        specs = build_specs(inputs)
        outcome = run_sweep(specs, args.workers, args.scheduler, not args.no_progress)
        csv_path, json_path = write_table(outcome.rows, args.out)
    except SweepError as err:
        print_error(PROG, err)
        return EXIT_REFUSED
    except AtlasControlError as err:
        print_error(PROG, err)
        return EXIT_REFUSED
    except KeyboardInterrupt:  # before any run finished: nothing to keep
        print(f'{PROG}: interrupted before any run finished; nothing written', file=sys.stderr)
        return EXIT_INTERRUPTED
    if outcome.interrupted:
        print(f'{PROG}: interrupted: kept the {len(outcome.rows)} of {outcome.total} runs that '
              f'finished in {csv_path} and {json_path}', file=sys.stderr)
        return EXIT_INTERRUPTED
    up = sum(not row['fell'] for row in outcome.rows)
    print(f'sweep: {len(outcome.rows)} runs, {up} stayed up; table: {csv_path}, {json_path}')
    return 0
