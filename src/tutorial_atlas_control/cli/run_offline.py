"""Command line of run_offline.py: play a trajectory, or a recorded AtlasSimInterface
session, offline (no ROS) and summarize the run."""

from __future__ import annotations

import argparse
import tempfile
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np

from tutorial_atlas_control.bags import analyze_bag, short_summary, summarise_walk, walk_lines
from tutorial_atlas_control.cli.convention import EXIT_INTERRUPTED, EXIT_REFUSED, print_error
from tutorial_atlas_control.course import (
    MUD_DAMPING,
    STARTS,
    CourseError,
    Start,
    check_mud_damping,
    parse_start,
    world_start,
)
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.offline import (
    DEFAULT_SETTLE_S,
    DEFAULT_START_AFTER_S,
    OfflineWorld,
    named_world,
    run_asi_offline,
    run_offline,
)
from tutorial_atlas_control.sim import DEFAULT_GAINS_FILE
from tutorial_atlas_control.trajectories import locate_trajectory_file

PROG = 'run_offline.py'


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'{text!r} is not a number of seconds') from None
    if not (np.isfinite(value) and value >= 0.0):
        raise argparse.ArgumentTypeError(f'{text!r} must be a finite number of seconds >= 0')
    return value


def _mud_damping(text: str) -> float:
    try:
        return check_mud_damping(float(text), '--mud-damping')
    except (ValueError, CourseError) as err:  # CourseError is a ValueError: one line
        raise argparse.ArgumentTypeError(str(err) if isinstance(err, CourseError) else
                                         f'{text!r} is not a number (N s/m)') from None


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (its --help is the documentation)."""
    parser = argparse.ArgumentParser(
        prog=PROG, description=(
            'Play trajectory NAME of YAML_FILE into the simulator without ROS, as `make demo` '
            'plays it live (User mode after --start-after s, traj_yaml\'s 50 Hz commands with '
            'the gains of --gains, then --settle s), deterministically and faster than real '
            'time. Prints the demo\'s summary; with --bag, also keeps the run as a ROS 1 bag '
            'that analyze_bag.py, replay_bag.py and rosbag read as a recorded run.'))
    parser.add_argument('trajectory_file', metavar='YAML_FILE', nargs='?',
                        help='trajectory file')
    parser.add_argument('name', metavar='NAME', nargs='?', help='trajectory name in YAML_FILE')
    parser.add_argument('--asi-from', type=Path, metavar='IN.bag',
                        help='instead of a trajectory, play the AtlasSimInterface commands '
                             'recorded in IN.bag (a walking client\'s, say) into a simulator '
                             'started as that run was, each at the sim time it was recorded '
                             'at, then --settle s; the summary adds the walk\'s steps, '
                             'distance, worst placement and falls')
    parser.add_argument('--behaviour', default='', metavar='MODULE:CLASS',
                        help='with --asi-from: a behaviour of your own in the library, as '
                             'atlas.launch\'s behaviour argument had it (module:Class or '
                             'path/to/file.py:Class)')
    parser.add_argument('--bag', type=Path, metavar='OUT.bag',
                        help='write the run to this bag (replaced if it exists)')
    parser.add_argument('--table', action='store_true',
                        help='list the tracking error of every joint that moved, not only the '
                             'worst three')
    parser.add_argument('--settle', type=_seconds, default=DEFAULT_SETTLE_S, metavar='S',
                        help='sim time after the last command (default: %(default)g)')
    parser.add_argument('--play-after', type=_seconds, default=0.0, metavar='S',
                        help='sim time between the switch to User and the first command '
                             '(default: 0; a live traj_yaml.py starts a few seconds after)')
    parser.add_argument('--scans', action='store_true',
                        help='write the head laser\'s scans too, as a live run\'s bag has them '
                             '(about a fifth more time; a trajectory run only)')
    parser.add_argument('--start-after', type=_seconds, default=DEFAULT_START_AFTER_S,
                        metavar='S', help='sim time from spawn to User mode and the first '
                        'command (default: %(default)g; the torso is pinned for 1 s)')
    parser.add_argument('--gains', type=Path, default=DEFAULT_GAINS_FILE, metavar='FILE',
                        help='controller gains YAML (default: config/atlas_controller.yaml)')
    parser.add_argument('--world', type=_world, metavar='NAME',
                        help='simulate DRCSim\'s VRC Task 2 world NAME (' + ', '.join(STARTS)
                        + '): the course\'s model, the robot at that world\'s start (default: '
                        'the flat world at the origin; with --asi-from: the recorded run\'s)')
    parser.add_argument('--start', type=_start, metavar='START',
                        help="start the robot at START: a world's start by name or 'x y z "
                             "yaw' (m, rad; the soles put on the ground, z a hint only), in "
                             'the flat world or --world\'s')
    parser.add_argument('--mud-damping', type=_mud_damping, default=MUD_DAMPING, metavar='C',
                        help="the mud's damping, N s/m, in a world with mud, as the node's "
                             '~mud_damping (default: %(default)g; the VRC finals: 70)')
    return parser


def _world(text: str) -> str:
    try:
        return world_start(text).name
    except CourseError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def _start(text: str) -> Start | None:
    try:
        return parse_start(text)
    except CourseError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def _offline_world(world: str | None, start: Start | None,
                   mud_damping: float = MUD_DAMPING) -> OfflineWorld | None:
    """The model, start and mud --world, --start and --mud-damping ask for (None: none)."""
    chosen = named_world(world) if world is not None else None
    if start is not None:
        chosen = OfflineWorld(start=start) if chosen is None else replace(chosen, start=start)
    if mud_damping != MUD_DAMPING:
        chosen = replace(chosen or OfflineWorld(), mud_damping=mud_damping)
    return chosen


def main(argv: Sequence[str] | None = None) -> int:
    """The command line; returns the exit status (1: bad input or failed run, nothing written)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.asi_from is not None and args.trajectory_file is not None:
        parser.error('--asi-from plays a recorded session: give no YAML_FILE and NAME')
    if args.asi_from is None and args.name is None:
        parser.error('give YAML_FILE and NAME (or --asi-from IN.bag)')
    if args.behaviour and args.asi_from is None:
        parser.error('--behaviour serves the AtlasSimInterface: it needs --asi-from')
    try:
        with tempfile.TemporaryDirectory(prefix='tac_offline_') as scratch:
            # Without --bag the summary is read from a bag that is deleted afterwards.
            bag = args.bag if args.bag is not None else Path(scratch) / 'offline.bag'
            world = _offline_world(args.world, args.start, args.mud_damping)
            if args.asi_from is not None:
                run = run_asi_offline(args.asi_from, bag, args.settle, args.gains,
                                      args.behaviour, world)
                what = f'{args.asi_from}: {run.commands} AtlasSimInterface commands applied'
            else:
                trajectory_file = locate_trajectory_file(args.trajectory_file, announce=print)
                run = run_offline(trajectory_file, args.name, bag, args.settle,
                                  args.start_after, args.gains, world, args.play_after,
                                  scans=args.scans)
                what = f'{args.name}: {run.commands} commands'
            analysis = analyze_bag(run.bag)
            walk = summarise_walk(analysis.data) if args.asi_from is not None else None
    except AtlasControlError as err:
        print_error(PROG, err)
        return EXIT_REFUSED
    except KeyboardInterrupt:  # the run leaves no partial bag behind
        return EXIT_INTERRUPTED
    print(f'offline: {what}, {run.sim_time_s:.3f} s of sim time in {run.wall_s:.2f} s '
          f'({run.real_time_factor:.1f}x real time)')
    if walk is None:
        print(short_summary(analysis, args.table))
    else:  # the walk's lines say whether it fell
        print('=== summary ===')
        for line in walk_lines(walk):
            print(line)
    if args.bag is not None:
        print(f'bag:   {run.bag}')
    return 0
