"""Command line of course_sweep.py: the VRC course walked offline over its variants x seeds on
Dask, and the table of how far each variant got (Markdown, CSV and JSON)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from tutorial_atlas_control.cli.convention import (
    EXIT_INTERRUPTED,
    EXIT_REFUSED,
    add_dask_arguments,
    print_error,
    seed_or_none,
)
from tutorial_atlas_control.course import COURSE_VARIANTS, GATES, STARTS
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.search import (
    COURSE_COLUMNS,
    atomic_write,
    check_output,
    course_specs,
    run_course_sweep,
    variant_lines,
    variant_table,
    write_table,
)

PROG = 'course_sweep.py'


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (its --help is the documentation)."""
    parser = argparse.ArgumentParser(
        prog=PROG, description=(
            'Walk the VRC Task 2 course offline as vrc_walker.py walks it live (its legs gate '
            'to gate, each planned from where the feet are, streamed through the '
            "AtlasSimInterface, scored by DRCSim's rules) on each variant of the course, once "
            'per seed (a perturbed start), in parallel on Dask distributed; write every run '
            '(OUT.csv, OUT.json) and the table per variant (OUT.md, also printed): runs '
            'through to the last gate without a fall, gates passed, falls, the course clock, '
            'and where the robot came closest to falling. A run costs 300-1000 CPU s.'))
    parser.add_argument('--variants', nargs='+', default=[v.name for v in COURSE_VARIANTS],
                        choices=[v.name for v in COURSE_VARIANTS], metavar='NAME',
                        help='course variants (default: all: %(default)s)')
    parser.add_argument('--seeds', type=seed_or_none, nargs='+', default=[1, 2, 3, 4],
                        metavar='SEED', help="start seeds, or 'none' (default: 1 2 3 4)")
    parser.add_argument('--world', default='vrc_task_2', choices=sorted(STARTS),
                        metavar='WORLD', help='the start (a VRC Task 2 world; default: '
                                              '%(default)s, the pen)')
    parser.add_argument('--to', default=GATES[-1].name, choices=[g.name for g in GATES],
                        metavar='GATE', help='the last gate (default: %(default)s)')
    parser.add_argument('--out', type=Path, default=Path('course_sweep'), metavar='OUT',
                        help='prefix: OUT.csv, OUT.json, OUT.md (default: %(default)s)')
    add_dask_arguments(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """The command line; returns the exit status (1: bad input, nothing written)."""
    args = build_parser().parse_args(argv)
    try:
        specs = course_specs(args.variants, args.seeds, args.world, args.to)
        check_output(args.out)
        outcome = run_course_sweep(specs, args.workers, args.scheduler, not args.no_progress)
        if not outcome.rows:
            raise KeyboardInterrupt
        csv_path, json_path = write_table(outcome.rows, args.out, COURSE_COLUMNS)
        table = variant_table(variant_lines(outcome.rows), args.to)
        md_path = args.out.with_name(args.out.name + '.md')
        atomic_write(md_path, table)
    except AtlasControlError as err:
        print_error(PROG, err)
        return EXIT_REFUSED
    except KeyboardInterrupt:  # before any run finished: nothing to keep
        print(f'{PROG}: interrupted before any run finished; nothing written', file=sys.stderr)
        return EXIT_INTERRUPTED
    print(table, end='')
    if outcome.interrupted:
        print(f'{PROG}: interrupted: kept the {len(outcome.rows)} of {outcome.total} runs that '
              f'finished in {csv_path}, {json_path} and {md_path}', file=sys.stderr)
        return EXIT_INTERRUPTED
    print(f'{PROG}: {len(outcome.rows)} runs; table: {md_path}; runs: {csv_path}, {json_path}')
    return 0
