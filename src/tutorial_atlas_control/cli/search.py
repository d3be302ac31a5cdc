"""Command line of search.py: CMA-ES over a trajectory's waypoints (and gains), through sweep."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from tutorial_atlas_control.cli.convention import (
    EXIT_INTERRUPTED,
    EXIT_REFUSED,
    add_dask_arguments,
    print_error,
    whole_number,
)
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.search import (
    OBJECTIVES,
    RunSpec,
    SearchProblem,
    SearchResult,
    SweepEngine,
    SweepInputs,
    atomic_write,
    build_specs,
    check_output,
    gains_yaml,
    parse_latency,
    parse_objective,
    parse_parameter,
    run_search,
    trajectory_yaml,
)
from tutorial_atlas_control.sim import DEFAULT_GAINS_FILE

PROG = 'search.py'


def _variant(text: str) -> tuple[float, float]:
    try:
        gain, time = (float(part) for part in text.split(':'))
    except ValueError:
        raise argparse.ArgumentTypeError(f'{text!r} is not GAIN:TIME (e.g. 0.9:1)') from None
    if not (0.0 < gain < float('inf') and 0.0 < time < float('inf')):
        raise argparse.ArgumentTypeError(f'{text!r}: both scales must be finite and > 0')
    return gain, time


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (its --help is the documentation)."""
    objectives = '; '.join(f'{name} ({", ".join(f"{k}={v:g}" for k, v in defaults.items())}): '
                           f'{what}' for name, (_, defaults, what) in OBJECTIVES.items())
    parser = argparse.ArgumentParser(
        prog=PROG, description=(
            'Search with CMA-ES for a variant of trajectory NAME of YAML_FILE that meets '
            'OBJECTIVE, each candidate an offline run on Dask (as sweep.py). Writes the best '
            'as trajectory --as in --yaml (the tutorial\'s format: traj_yaml.py plays it) and, '
            'if gains are searched, --gains-out. Objectives: ' + objectives + '.'))
    parser.add_argument('trajectory_file', metavar='YAML_FILE', help='starting trajectory file')
    parser.add_argument('name', metavar='NAME', help='starting trajectory name')
    parser.add_argument('--objective', required=True, metavar='NAME[:KEY=VALUE,...]',
                        help='what to minimise, e.g. step_forward:dx=0.15,stand=5')
    parser.add_argument('--vary', action='append', default=[], metavar='W:JOINTS',
                        help='an offset (rad) on waypoint W (index, W+W, or all) of a signed '
                             'joint sum, e.g. 0:l_leg_lax+r_leg_lax-l_leg_mhx-r_leg_mhx')
    parser.add_argument('--vary-duration', action='append', default=[], metavar='W',
                        help='a factor on waypoint W\'s duration')
    parser.add_argument('--vary-gain', action='append', default=[], metavar='JOINTS',
                        help='a factor on the p and d of these joints, e.g. l_leg_mhx+r_leg_mhx')
    parser.add_argument('--gains', default=str(DEFAULT_GAINS_FILE), metavar='FILE',
                        help='starting gains (default: config/atlas_controller.yaml)')
    parser.add_argument('--seed', type=int, default=0, help='CMA-ES seed (default: 0)')
    parser.add_argument('--popsize', type=whole_number(1), default=6, metavar='N',
                        help='candidates per generation (default: %(default)s)')
    parser.add_argument('--generations', type=whole_number(1), default=10, metavar='N',
                        help='generations in all, counting resumed ones (default: %(default)s)')
    parser.add_argument('--step-scale', type=float, default=1.0, metavar='X',
                        help='factor on the initial steps (0.05 rad, 0.2 and 0.3 log-factors)')
    parser.add_argument('--robust', type=_variant, nargs='+', default=[],
                        metavar='GAIN:TIME',
                        help='also play each candidate with these gain and timing scales '
                             '(e.g. 0.9:1 1.1:1 1:0.9 1:1.1); its cost is the mean')
    parser.add_argument('--latency-ms', metavar='LO:HI',
                        help='with --latency-draws: each command delayed LO..HI ms, as live')
    parser.add_argument('--latency-draws', type=whole_number(0), default=0, metavar='N',
                        help='also play each candidate N times with --latency-ms (the same N '
                             'draws for every candidate); its cost is the mean (default: 0)')
    parser.add_argument('--log', type=Path, required=True, metavar='FILE',
                        help='the search log (JSON lines)')
    parser.add_argument('--resume', action='store_true', help='continue the search in --log')
    parser.add_argument('--yaml', type=Path, required=True, metavar='OUT.yaml',
                        help='where the best trajectory is written')
    parser.add_argument('--as', dest='out_name', metavar='NAME',
                        help='its name in OUT.yaml (default: NAME_found)')
    parser.add_argument('--gains-out', type=Path, metavar='FILE',
                        help='where the best gains are written (default: OUT_gains.yaml beside '
                             '--yaml, when gains are searched)')
    add_dask_arguments(parser, progress=False)
    return parser


def _writer(args: argparse.Namespace, problem: SearchProblem,
            gains_out: Path | None) -> Callable[[SearchResult], None]:
    """Writes the best so far (each time it improves: an interrupted search keeps it)."""
    def write(result: SearchResult) -> None:
        row = result.best_row
        comment = [
            f'Found by search.py from {problem.base.name} ({problem.base.trajectory}),',
            f'objective {problem.objective.text()}, seed {problem.seed}: cost '
            f'{result.best_cost:.4g} (start {result.start_cost:.4g}).',
            f'Offline: fell {row["fell"]}, right foot {row["r_foot_dx_m"]:+.3f} m forward, '
            f'stood {row["stood_after_s"]:.2f} s after, pelvis {row["pelvis_z_end_m"]:.3f} m.']
        if gains_out is not None:
            comment.append(f'Needs its gains: gains_file:={gains_out}')
            atomic_write(gains_out, gains_yaml(result.best_spec, comment[:2]))
        name = args.out_name or f'{args.name}_found'
        atomic_write(args.yaml, trajectory_yaml(name, result.best_spec, comment))
    return write


def main(argv: Sequence[str] | None = None) -> int:
    """The command line; returns the exit status (1: bad input, nothing written)."""
    args = build_parser().parse_args(argv)
    try:
        objective = parse_objective(args.objective)
        for path in (args.log, args.yaml, args.gains_out):
            if path is not None:
                check_output(path)
        if args.resume and not args.log.is_file():
            raise AtlasControlError(f'cannot resume from {args.log}: no such file')
        if not args.resume and args.log.exists():
            raise AtlasControlError(f'{args.log} exists; give --resume to continue that '
                                    'search, or another --log')
        specs = build_specs(SweepInputs([(args.trajectory_file, args.name)], [args.gains],
                                        settle_s=objective.settle_s, seed=args.seed))
        base: RunSpec = specs[0]
        count = len(base.waypoints)
        parameters = ([parse_parameter('joint', t, count) for t in args.vary]
                      + [parse_parameter('duration', t, count) for t in args.vary_duration]
                      + [parse_parameter('gain', t, count) for t in args.vary_gain])
        if not parameters:
            raise AtlasControlError('nothing to search: give --vary, --vary-duration or '
                                    '--vary-gain')
        gains_out = None
        if args.vary_gain:
            gains_out = args.gains_out or args.yaml.with_name(args.yaml.stem + '_gains.yaml')
        if bool(args.latency_draws) != bool(args.latency_ms):
            raise AtlasControlError('give --latency-ms LO:HI and --latency-draws N (N >= 1) '
                                    'together')
        lo, hi = parse_latency(args.latency_ms) if args.latency_ms else (0, 0)
        problem = SearchProblem(base, parameters, objective, args.seed, args.popsize,
                                args.generations, args.step_scale, args.robust,
                                (lo, hi, args.latency_draws))
        with SweepEngine(args.workers, args.scheduler) as engine:
            result = run_search(problem, lambda s: engine.run(s, progress=False), args.log,
                                args.resume, on_best=_writer(args, problem, gains_out))
        if result.generations == 0 or result.best_x == [0.0] * len(parameters):
            _writer(args, problem, gains_out)(result)
    except AtlasControlError as err:
        print_error(PROG, err)
        return EXIT_REFUSED
    except KeyboardInterrupt:
        print(f'{PROG}: interrupted; the log {args.log} keeps the finished generations',
              file=sys.stderr)
        return EXIT_INTERRUPTED
    if result.interrupted:
        print(f'{PROG}: interrupted after generation {result.generations}; --resume continues '
              f'it; best so far in {args.yaml}', file=sys.stderr)
        return EXIT_INTERRUPTED
    row = result.best_row
    print(f'search: {result.generations} generations: cost {result.start_cost:.4g} -> '
          f'{result.best_cost:.4g}; fell {row["fell"]}, right foot {row["r_foot_dx_m"]:+.3f} m, '
          f'stood {row["stood_after_s"]:.2f} s after; wrote {args.yaml}'
          + (f' and {gains_out}' if gains_out else ''))
    return 0
