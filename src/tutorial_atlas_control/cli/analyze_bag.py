"""Command line of analyze_bag.py: summarize a recorded run, optionally as JSON/CSV/plot."""

from __future__ import annotations

import argparse
import sys
from typing import Sequence

from tutorial_atlas_control.bags.analysis import (
    COMMAND_CHANGE_RAD,
    EFFORT_LIMIT_TOLERANCE_NM,
    FALL_HEIGHT_M,
    MOVED_RANGE_RAD,
    analyze_bag,
)
from tutorial_atlas_control.bags.compare import compare_bags, format_comparison, plot_comparison
from tutorial_atlas_control.bags.compare import to_json as comparison_json
from tutorial_atlas_control.bags.render import (
    DEFAULT_FPS,
    DEFAULT_SIZE,
    check_output_path,
    parse_fps,
    parse_size,
    render_bag_video,
)
from tutorial_atlas_control.bags.report import format_summary, plot_run, to_json, write_csv
from tutorial_atlas_control.bags.run_log import PlayedTrajectory, played_trajectories
from tutorial_atlas_control.cli.convention import (
    EXIT_INTERRUPTED,
    EXIT_REFUSED,
    argument_type,
    print_error,
)
from tutorial_atlas_control.errors import AtlasControlError

PROG = 'analyze_bag.py'

DESCRIPTION = """\
Summarize a run recorded with `rosbag record` (reads the bag with rosbags; no roscore).

Reports the bag's duration, every topic with type, message count and rate; the control
mode timeline (/atlas/control_mode); whether and when the robot fell (first time the
pelvis height in /ground_truth_odom drops below {fall} m); for each joint that moved
(measured range > {moved} rad, or a commanded position that changes by more than
{change:g} rad) the RMS and max tracking error: at every /atlas/joint_states stamp, the
latest /atlas/joint_commands position at or before it (zero-order hold, per joint,
names matched without 'atlas::', empty names = tutorial order) minus the measured
position; the command rate and the command age (state stamp minus latest command stamp);
and the joints that reached their effort limit (|effort| >= limit - {tol} N·m) and for
how long.

Times are header stamps (sim time) where messages have them, bag record time otherwise,
given in seconds from the bag's start.
"""

EPILOG = """\
JSON keys (--json): bag, start_time (s), duration (s), topics {name: {type, count,
rate (Hz or null)}}, mode_timeline [{time (s), mode}], inputs [{time (s), input}]
(VRCPlugin's inputs the simulator applied, also on the text timeline), fell (bool, null without
odometry), fall_time (s or null), min_pelvis_height (m), joints {name: {rms_error,
max_error (rad), samples, commanded, measured_range (rad)}} (joints that moved),
command_rate (Hz), command_count, command_age {mean, max} (s), effort_saturation
{name: {limit (N·m), duration (s), first_time (s), samples}}, thresholds,
unavailable {metric: reason}, warnings [text].

With a player's start line on /rosout (traj_yaml.py, run_offline.py), the summary names the
trajectory played (JSON: trajectory {file, name} or null).

--compare B.bag (JSON keys): a, b {bag, trajectory}, aligned_on {event, time_a, time_b (s
from each bag's start), window [s, s]}, joints {name: {rms_diff, max_diff, command_rms_diff
(rad, A - B)}}, pelvis_height_rms_diff (m), fall_time_a, fall_time_b (s from the first
applied command, null: did not fall). The runs are aligned on their first applied joint
command (the first /atlas/joint_commands at or after the switch to User mode) and compared
at A's joint states over the time both cover after it.

Exit status: 0 on success (also when some metrics are unavailable), 1 when the bag
cannot be read (missing, not a bag, unindexed: run `rosbag reindex BAG`) or an output
cannot be written, 2 on bad arguments.

Video (--video): each frame poses the model as recorded at the frame's time (pelvis
from /ground_truth_odom, interpolated; joints from /atlas/joint_states) and draws it
offscreen through the model's `track` camera (software OSMesa when there is no display);
each frame is labelled with its time from the bag's start. Needs both topics.

Example: rosrun tutorial_atlas_control analyze_bag.py run.bag --plot run.png --csv run_csv
         rosrun tutorial_atlas_control analyze_bag.py run.bag --video run.mp4 --fps 30
"""


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (its --help is the documentation)."""
    parser = argparse.ArgumentParser(
        prog=PROG, formatter_class=argparse.RawDescriptionHelpFormatter,
        description=DESCRIPTION.format(fall=FALL_HEIGHT_M, moved=MOVED_RANGE_RAD,
                                       change=COMMAND_CHANGE_RAD, tol=EFFORT_LIMIT_TOLERANCE_NM),
        epilog=EPILOG)
    parser.add_argument('bag', metavar='BAG', help='the ROS 1 .bag file to analyze')
    parser.add_argument('--compare', metavar='B.bag',
                        help='compare BAG (A) with this run (B), aligned on their first applied '
                             'joint command: per joint RMS/max difference of measured and '
                             'commanded positions, pelvis height, fall times; --json and --plot '
                             'then apply to the comparison')
    parser.add_argument('--json', action='store_true',
                        help='print the results as one JSON object instead of the text summary')
    parser.add_argument('--plot', metavar='FILE.png',
                        help='write commanded vs measured positions of the joints that moved and '
                             'the pelvis height, with mode changes marked, to this image')
    parser.add_argument('--csv', metavar='DIR',
                        help='write joint_states.csv (t, <joint>_position..., _velocity..., '
                             '_effort...), joint_commands.csv (t, <joint>_position as sent, nan = '
                             'not sent) and pelvis_pose.csv (t, x y z, qx qy qz qw, vx vy vz, '
                             'wx wy wz) into this directory (created if needed)')
    parser.add_argument('--video', metavar='FILE.mp4',
                        help='render the run offscreen to this video: .mp4 (H.264) or .gif')
    parser.add_argument('--fps', type=argument_type(parse_fps), default=DEFAULT_FPS,
                        help='video frames per second of sim time (default: %(default)g)')
    parser.add_argument('--size', metavar='WxH', type=argument_type(parse_size),
                        default='{}x{}'.format(*DEFAULT_SIZE),
                        help='video size in pixels (default: %(default)s)')
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.compare:
        if args.csv or args.video:
            parser.error('--csv and --video describe one run; leave them out with --compare')
        return _compare(args)
    try:
        if args.video:  # fail on a bad output before reading and analyzing the bag
            check_output_path(args.video, *args.size, args.fps)
        analysis = analyze_bag(args.bag)
        played = played_trajectories(args.bag)
        print(to_json(analysis, {'trajectory': _played_dict(played)}) if args.json
              else format_summary(analysis, trajectory=_played_text(played)))
        if args.csv:
            for path in write_csv(analysis.data, args.csv):
                print(f'wrote {path}', file=sys.stderr)
        if args.plot:
            print(f'wrote {plot_run(analysis, args.plot)}', file=sys.stderr)
        if args.video:
            video = render_bag_video(analysis.data, args.video, args.fps, args.size)
            print(f'wrote {video.path} ({video.frames} frames at {video.fps:g} fps)',
                  file=sys.stderr)
    except AtlasControlError as err:
        print_error(PROG, err)
        return EXIT_REFUSED
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    return 0


def _played_dict(played: list[PlayedTrajectory]) -> dict[str, str] | None:
    return {'file': played[0].file, 'name': played[0].name} if played else None


def _played_text(played: list[PlayedTrajectory]) -> str | None:
    return ', then '.join(p.describe() for p in played) if played else None


def _compare(args: argparse.Namespace) -> int:
    """`BAG --compare B.bag`: bag_compare's report, JSON or plot."""
    try:
        comparison = compare_bags(args.bag, args.compare)
        print(comparison_json(comparison) if args.json else format_comparison(comparison))
        if args.plot:
            print(f'wrote {plot_comparison(comparison, args.plot)}', file=sys.stderr)
    except AtlasControlError as err:
        print_error(PROG, err)
        return EXIT_REFUSED
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    return 0
