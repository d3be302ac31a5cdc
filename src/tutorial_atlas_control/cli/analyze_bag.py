"""Command line of analyze_bag.py: summarize a recorded run, optionally as JSON/CSV/plot."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any, Sequence

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags import (
    COMMAND_CHANGE_RAD,
    DEFAULT_FPS,
    DEFAULT_SIZE,
    EFFORT_LIMIT_TOLERANCE_NM,
    MOVED_RANGE_RAD,
    WORST_JOINTS,
    Analysis,
    PlayedTrajectory,
    WalkSummary,
    analysis_to_json,
    analyze,
    analyze_try,
    behaviour_lines,
    capture_trace,
    check_output_path,
    compare_analyses,
    comparison_to_json,
    format_comparison,
    format_summary,
    is_course_run,
    laser_height_map,
    map_error_lines,
    parse_fps,
    parse_size,
    plot_behaviours,
    plot_capture,
    plot_comparison,
    plot_course_map,
    plot_footprints,
    plot_joints,
    plot_run,
    read_bag,
    read_behaviours,
    read_laser_scans,
    read_scores,
    read_step_targets,
    recorded_course_run,
    render_bag_video,
    scan_cloud,
    score_lines,
    summarise_walk,
    titled_walks,
    walk_lines,
    write_csv,
)
from tutorial_atlas_control.cli.convention import (
    EXIT_INTERRUPTED,
    EXIT_REFUSED,
    add_bag_arguments,
    argument_type,
    check_bag_arguments,
    chosen_bag,
    print_error,
)
from tutorial_atlas_control.errors import AtlasControlError, BagAnalysisError
from tutorial_atlas_control.sim import FALL_HEIGHT_M

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
given in seconds from the bag's start; after a /gazebo/reset_simulation (sim time back to
0) they go on from where the run stopped, plus 1 s.

Tries: a launch in which the robot was reset between trajectories (/gazebo/reset_world,
/gazebo/reset_simulation, the viewer's reset) holds several tries. The bag is split at
each reset (the re-published /atlas/sim_config, and sim time going back), each try gets
its own summary (trajectory, fall and its time from the try's first applied command,
commands, tracking), and the plot marks the resets and every fall. --try N (or --start,
--end) limits the summary, plot, CSV and video to one try.
"""

EPILOG = """\
JSON keys (--json): bag, start_time (s), duration (s), topics {name: {type, count,
rate (Hz or null)}}, mode_timeline [{time (s), mode}], inputs [{time (s), input}]
(VRCPlugin's inputs the simulator applied, also on the text timeline), fell (bool, null without
odometry), fall_time (s or null), min_pelvis_height (m), joints {name: {rms_error,
max_error (rad), samples, commanded, measured_range (rad)}} (joints that moved),
command_rate (Hz), command_count, command_age {mean, max} (s), effort_saturation
{name: {limit (N·m), duration (s), first_time (s), samples}}, thresholds,
unavailable {metric: reason}, warnings [text] (one when the bag holds several tries),
tries [{try (number from 1), start, end (s), sim_start (s of sim time), began_with
(start, reset_world, reset_simulation, sim time went back), trajectory {file, name} or
null, trajectories, mode_timeline, first_command (s), fell, fall_time (s),
fall_after_command (s from the try's first applied command), min_pelvis_height,
command_count, command_rate, command_age, joints}]. Whole-run command_rate and
command_age count each try's commands alone, while they arrive.

With a player's start line on /rosout (traj_yaml.py, run_offline.py), the summary names the
trajectory played (JSON: trajectory {file, name} or null).

--compare B.bag compares A's try --try N (default: its last) with B's try --try-b M
(default: its last). JSON keys: a, b {bag, trajectory}, aligned_on {event, time_a, time_b (s
from each bag's start), window [s, s]}, joints {name: {rms_diff, max_diff, command_rms_diff
(rad, A - B)}}, pelvis_height_rms_diff (m), fall_time_a, fall_time_b (s from the first
applied command, null: did not fall). The runs are aligned on their first applied joint
command (the first /atlas/joint_commands at or after the switch to User mode) and compared
at A's joint states over the time both cover after it.

Exit status: 0 on success (also when some metrics are unavailable), 1 when the bag
cannot be read (missing, not a bag, unindexed or truncated: run `rosbag reindex BAG`), has
no such try, or an output cannot be written, 2 on bad arguments.

Video (--video): each frame poses the model as recorded at the frame's time (pelvis
from /ground_truth_odom, interpolated; joints from /atlas/joint_states) and draws it
offscreen through the model's `track` camera (software OSMesa when there is no display);
each frame is labelled with its time from the bag's start. Needs both topics.

Without BAG (or with --latest), the newest .bag in atlas.launch's bag directory
($TAC_BAG_DIR, else ~/.ros/tutorial_atlas_control/bags) is analyzed.

Example: rosrun tutorial_atlas_control analyze_bag.py --latest --plot run.png
         rosrun tutorial_atlas_control analyze_bag.py run.bag --try 2 --video try2.mp4 --fps 30
         rosrun tutorial_atlas_control analyze_bag.py run.bag --try 1 --compare run.bag --try-b 3
"""


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (its --help is the documentation)."""
    parser = argparse.ArgumentParser(
        prog=PROG, formatter_class=argparse.RawDescriptionHelpFormatter,
        description=DESCRIPTION.format(fall=FALL_HEIGHT_M, moved=MOVED_RANGE_RAD,
                                       change=COMMAND_CHANGE_RAD, tol=EFFORT_LIMIT_TOLERANCE_NM),
        epilog=EPILOG)
    add_bag_arguments(parser, 'analyze')
    parser.add_argument('--try', dest='try_number', metavar='N', type=int,
                        help='only try N (from 1; -1 is the last) of a bag with resets: the '
                             'summary, --plot, --csv, --video and --compare')
    parser.add_argument('--start', type=float, metavar='S',
                        help='only from S seconds from the bag\'s start (as the times shown)')
    parser.add_argument('--end', type=float, metavar='S',
                        help='only up to S seconds from the bag\'s start')
    parser.add_argument('--try-b', dest='try_b', metavar='M', type=int,
                        help='with --compare: B\'s try to compare (default: its last)')
    parser.add_argument('--compare', metavar='B.bag',
                        help='compare BAG (A) with this run (B), aligned on their first applied '
                             'joint command: per joint RMS/max difference of measured and '
                             'commanded positions, pelvis height, fall times; --json and --plot '
                             'then apply to the comparison')
    parser.add_argument('--json', action='store_true',
                        help='print the results as one JSON object instead of the text summary')
    parser.add_argument('--plot', metavar='FILE.png',
                        help='write the run at a glance to this image: pelvis height and each '
                             'fall (sim time, s after the try\'s first command), the tries with '
                             'their trajectories and waypoints, control modes, and the '
                             f'{WORST_JOINTS} worst-tracked joints\' error')
    parser.add_argument('--course-map', metavar='FILE.png',
                        help='write the VRC Task 2 course from above with the run on it: the '
                             'terrain shaded, the pen, the gates, the mud box, the blocks, the '
                             'pelvis\'s path, the feet\'s landings, falls and the score\'s events '
                             '(a course run only; --plot run.png writes it as run.course.png)')
    parser.add_argument('--scan-cloud', action='store_true',
                        help='with --course-map: the head laser\'s recorded scans over it, each '
                             'range a point in the world (the head\'s recorded pose, the spindle '
                             'simulated from set_spindle_speed), coloured by height')
    parser.add_argument('--laser-map', action='store_true',
                        help='the head laser\'s height map of the run\'s scans (as a course '
                             'walker builds it: sensors/height_map.py) at the footsteps its WALK '
                             'commands asked for: how many it saw, its error against the '
                             'course\'s description')
    parser.add_argument('--plot-joints', metavar='FILE.png',
                        help='write commanded vs measured positions of every joint that moved '
                             '(one panel each) and the pelvis height to this image')
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


def _check_arguments(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Exit 2 (argparse) on options that contradict each other."""
    check_bag_arguments(parser, args)
    if args.try_number is not None and (args.start is not None or args.end is not None):
        parser.error('give --try or --start/--end, not both')
    if args.start is not None and args.end is not None and args.end <= args.start:
        parser.error(f'--end {args.end:g} must be after --start {args.start:g}')
    if args.try_b is not None and not args.compare:
        parser.error('--try-b chooses the try of the --compare bag; give --compare B.bag')
    if args.scan_cloud and not args.course_map:
        parser.error('--scan-cloud draws on the course map: give --course-map FILE.png')
    if args.compare and (args.csv or args.video or args.course_map):
        parser.error('--csv, --video and --course-map describe one run; leave them out with '
                     '--compare')


def _chosen(path: str, args: argparse.Namespace) -> Analysis:
    """The analysis of the bag, or of the try or time window the options choose."""
    data = read_bag(path)
    if args.try_number is not None:
        return analyze_try(data, args.try_number)
    return analyze(data, args.start, args.end)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    _check_arguments(parser, args)
    try:
        args.bag = chosen_bag(args, 'analyzing')
        if args.compare:
            return _compare(args)
        if args.video:  # fail on a bad output before reading and analyzing the bag
            check_output_path(args.video, *args.size, args.fps)
        analysis = _chosen(args.bag, args)
        _check_course_map(analysis, args)  # before any output: a refusal is one line
        played = [p for _, p in analysis.data.played]
        walk = summarise_walk(analysis.data)
        changes = read_behaviours(analysis.data)
        walks = titled_walks(analysis.data, changes)
        scores = read_scores(analysis.data)
        extra = (behaviour_lines(changes) if changes is not None else []) + [
            line for title, each in walks for line in [title, *walk_lines(each)]] + (
            score_lines(scores) if scores is not None else []) + (
            _laser_map_lines(analysis) if args.laser_map else [])
        print(analysis_to_json(analysis, {
            'trajectory': _played_dict(played), 'walk': _walk_dict(walk),
            'walks': [_walk_dict(each) for _, each in walks],
            'behaviours': None if changes is None else [vars(c) for c in changes],
            'vrc_score': None if scores is None else [vars(s) for s in scores]})
              if args.json else format_summary(analysis, trajectory=_played_text(played))
              + ''.join(f'\n{line}' for line in extra))
        if args.csv:
            for path in write_csv(analysis.data, args.csv):
                print(f'wrote {path}', file=sys.stderr)
        if args.plot:
            print(f'wrote {plot_run(analysis, args.plot)}', file=sys.stderr)
            if walk is not None:  # and the walk seen from above, beside it
                footprints = Path(args.plot).with_suffix('.footprints.png')
                print(f'wrote {plot_footprints(walk, footprints)}', file=sys.stderr)
            pelvis = analysis.data.pelvis
            if changes and pelvis is not None:  # and the behaviours over time
                behaviours = plot_behaviours(changes, pelvis.t_s, pelvis.position_m[:, 2],
                                             Path(args.plot).with_suffix('.behaviours.png'))
                print(f'wrote {behaviours}', file=sys.stderr)
            trace = capture_trace(analysis.data) if walk is not None or changes else None
            if trace is not None:  # and the capture point against the support polygon
                capture = plot_capture(trace, Path(args.plot).with_suffix('.capture.png'))
                print(f'wrote {capture}', file=sys.stderr)
        for course_map in _course_maps(analysis, args):
            print(f'wrote {course_map}', file=sys.stderr)
        if args.plot_joints:
            print(f'wrote {plot_joints(analysis, args.plot_joints)}', file=sys.stderr)
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


def _check_course_map(analysis: Analysis, args: argparse.Namespace) -> None:
    """--course-map needs a course run, --scan-cloud a bag with scans.

    Raises:
        BagAnalysisError: the bag is not one.
    """
    if args.course_map and not is_course_run(analysis.data):
        raise BagAnalysisError(f'{analysis.data.path} is not a VRC Task 2 run (its '
                               '/atlas/sim_config names no vrc_task_2.xml and it has no '
                               '/vrc_score): --course-map draws course runs only')
    scans = analysis.data.topics.get(topics.LASER_SCAN)
    if (args.scan_cloud or args.laser_map) and not getattr(scans, 'count', 0):
        raise BagAnalysisError(f'{analysis.data.path} has no {topics.LASER_SCAN}: no scan to '
                               'draw or map')


def _laser_map_lines(analysis: Analysis) -> list[str]:
    """--laser-map's lines: the run's scans as a height map, at its WALK footsteps."""
    scans = read_laser_scans(analysis.data.path)
    if scans is None:
        return []
    targets, _ = read_step_targets(analysis.data)
    return map_error_lines(laser_height_map(analysis.data, scans),
                           [(target.x_m, target.y_m) for target in targets])


def _course_maps(analysis: Analysis, args: argparse.Namespace) -> list[Path]:
    """The course maps asked for: --course-map's, and --plot's beside it for a course run.

    Raises:
        BagAnalysisError: --course-map for a run without a pelvis pose.
    """
    data = analysis.data
    paths = ([Path(args.course_map)] if args.course_map else []) + (
        [Path(args.plot).with_suffix('.course.png')] if args.plot and is_course_run(data)
        else [])
    if not paths:
        return []
    run = recorded_course_run(data, read_scores(data))
    if run is None and args.course_map:
        raise BagAnalysisError(f'{data.path} has no pelvis pose (/ground_truth_odom): '
                               'no path to draw on the course map')
    cloud = None
    if args.scan_cloud:
        scans = read_laser_scans(data.path)
        cloud = None if scans is None else scan_cloud(data, scans)
    return [plot_course_map(run, path, cloud) for path in paths] if run is not None else []


def _walk_dict(walk: WalkSummary | None) -> dict[str, Any] | None:
    """The walk's figures for --json (None: the run had no WALK)."""
    if walk is None:
        return None
    bias = walk.placement_bias_m
    worst = walk.worst_placement
    return {'steps_asked': len(walk.placements), 'steps_taken': walk.steps_taken,
            'path_m': walk.path_m, 'displacement_m': walk.distance_m, 'fell': walk.fell,
            'lowest_pelvis_m': walk.lowest_pelvis_m,
            'placement_bias_ahead_m': None if bias is None else bias[0],
            'placement_bias_left_m': None if bias is None else bias[1],
            'placement_scatter_m': walk.placement_scatter_m,
            'worst_placement_m': None if worst is None else worst[0],
            'worst_placement_rad': None if worst is None else worst[1]}


def _played_dict(played: list[PlayedTrajectory]) -> dict[str, str] | None:
    return {'file': played[0].file, 'name': played[0].name} if played else None


def _played_text(played: list[PlayedTrajectory]) -> str | None:
    return ', then '.join(p.describe() for p in played) if played else None


def _compare(args: argparse.Namespace) -> int:
    """`BAG --compare B.bag`: bags/compare.py's report, JSON or plot, of A's and B's tries."""
    try:
        a = analyze_try(read_bag(args.bag), -1 if args.try_number is None else args.try_number)
        b = analyze_try(read_bag(args.compare), -1 if args.try_b is None else args.try_b)
        played_a = [p for _, p in a.data.played]
        played_b = [p for _, p in b.data.played]
        comparison = compare_analyses(a, b, played_a[0] if played_a else None,
                             played_b[0] if played_b else None)
        print(comparison_to_json(comparison) if args.json else format_comparison(comparison))
        if args.plot:
            print(f'wrote {plot_comparison(comparison, args.plot)}', file=sys.stderr)
    except AtlasControlError as err:
        print_error(PROG, err)
        return EXIT_REFUSED
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    return 0
