"""Command line of run_demo.py (`make demo`): the tutorial end to end, headless."""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from tutorial_atlas_control.bags import parse_size
from tutorial_atlas_control.cli.convention import (
    EXIT_INTERRUPTED,
    EXIT_REFUSED,
    argument_type,
    print_error,
)
from tutorial_atlas_control.demo import demo_node as demo
from tutorial_atlas_control.demo import walk_demo_node as walk_demo
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.sim import load_gains_yaml
from tutorial_atlas_control.trajectories import find_trajectory, gains_for, load_trajectory

PROG = 'run_demo.py'


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (its --help is the documentation)."""
    parser = argparse.ArgumentParser(prog=PROG, description=demo.__doc__.split('\n\n')[0])
    walks = '; '.join(f'{name}: {what}' for name, (what, _) in
                      {**walk_demo.WALKS, **walk_demo.COURSE_WALKS}.items())
    parser.add_argument('trajectory', nargs='?', default='step_and_fall',
                        help='trajectory name (default: step_and_fall); without --file it '
                             "must be in exactly one of the package's trajectories/*.yaml, "
                             'e.g. step_and_stand (trajectories/Stepping.yaml); or a walk '
                             'through the AtlasSimInterface (startup_mode:=bdi_stand and '
                             f'walk_client.py; the summary adds the footprints): {walks}')
    parser.add_argument('--file', type=Path,
                        help="trajectory YAML file (default: the one of the package's "
                             'trajectories/*.yaml that holds TRAJECTORY, e.g. Traj_data2.yaml '
                             'for step_and_fall)')
    parser.add_argument('--gains-file', type=Path, metavar='FILE',
                        help="controller gains YAML, atlas.launch's gains_file (default: the "
                             "trajectory file's companion ../config/<its stem in lower "
                             'case>_gains.yaml if it exists, e.g. config/stepping_gains.yaml '
                             'for trajectories/Stepping.yaml; else config/atlas_controller.yaml)')
    parser.add_argument('--bag-dir', type=Path,
                        default=Path(os.environ.get('TAC_BAG_DIR', demo.DEFAULT_BAG_DIR)),
                        help='where the bag goes (default: $TAC_BAG_DIR or %(default)s)')
    parser.add_argument('--real-time-factor', type=argument_type(real_time_factor), default=1.0,
                        help='simulator pace; 0 = as fast as possible (default: 1.0)')
    parser.add_argument('--table', action='store_true',
                        help='list the tracking error of every joint that moved, not only the '
                             'worst three')
    parser.add_argument('--video-fps', type=float, default=demo.DEMO_VIDEO_FPS,
                        help='frame rate of the rendered video; 0 = no video '
                             '(default: %(default)g)')
    parser.add_argument('--video-size', type=argument_type(parse_size),
                        default=demo.DEMO_VIDEO_SIZE,
                        help='video size WxH in pixels (default: %(default)s)')
    return parser


def real_time_factor(text: str) -> float:
    """A pace for atlas.launch: a finite number >= 0 (0: as fast as possible)."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0.0 <= value < math.inf:
        raise AtlasControlError(f'real time factor {text!r} is not a finite number >= 0')
    return value


def _warn(line: str) -> None:
    print(line, file=sys.stderr)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    args = build_parser().parse_args(argv)
    started_s = time.time()
    walk = args.file is None and (args.trajectory in walk_demo.WALKS
                                  or args.trajectory in walk_demo.COURSE_WALKS)
    if walk and (args.gains_file is not None or args.table):
        print_error(PROG, f'{args.trajectory} is a walk: --gains-file and --table apply to '
                          'trajectories only')
        return EXIT_REFUSED
    try:
        if walk:
            _walk(args)
        else:
            _play(args)
    except AtlasControlError as err:
        print_error(PROG, err)
        return EXIT_REFUSED
    except subprocess.TimeoutExpired as err:
        print_error(PROG, f'{err.cmd[2] if len(err.cmd) > 2 else err.cmd} timed out')
        return EXIT_REFUSED
    except KeyboardInterrupt:  # the demo has stopped roslaunch on the way out
        _name_partial_bag(args.bag_dir.expanduser().resolve(), started_s)
        return EXIT_INTERRUPTED
    return 0


def _play(args: argparse.Namespace) -> None:
    """run_demo.py TRAJECTORY: the tutorial's way, User mode and traj_yaml.py."""
    # Everything is checked before anything starts.
    walks = (*walk_demo.WALKS, *walk_demo.COURSE_WALKS)
    trajectory_file = args.file or find_trajectory(args.trajectory, walks=walks)
    load_trajectory(trajectory_file, args.trajectory)
    gains = gains_for(trajectory_file, args.gains_file)
    load_gains_yaml(gains.path)
    bag = demo.run_demo(args.trajectory, trajectory_file, args.bag_dir.expanduser().resolve(),
                        args.real_time_factor, args.bag_dir.expanduser() / 'logs',
                        progress=print, warn=_warn, gains=gains)
    demo.summarise(bag, args.video_fps, args.video_size, report=print, table=args.table)


def _walk(args: argparse.Namespace) -> None:
    """run_demo.py WALK: a walk through the AtlasSimInterface (the balancing Stand walks;
    the tutorial's gains are the user's PID's), on the VRC course for a COURSE_WALKS name."""
    run = walk_demo.run_course_demo if args.trajectory in walk_demo.COURSE_WALKS \
        else walk_demo.run_walk_demo
    bag = run(args.trajectory, args.bag_dir.expanduser().resolve(), args.real_time_factor,
              args.bag_dir.expanduser() / 'logs', progress=print, warn=_warn)
    demo.summarise(bag, args.video_fps, args.video_size, report=print, walk=True)


def _name_partial_bag(bag_dir: Path, started_s: float) -> None:
    """After Ctrl-C: where the run so far was recorded (the recorder closed it), if at all."""
    try:
        bag = demo.newest_bag(bag_dir, started_s)
    except (AtlasControlError, OSError):
        return  # interrupted before the recorder wrote anything
    print(f'{PROG}: interrupted; the run so far is in {bag} (analyze_bag.py {bag})',
          file=sys.stderr)
