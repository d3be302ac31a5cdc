"""Command line of replay_bag.py: re-simulate a recorded run offline and compare."""

from __future__ import annotations

import argparse
import json
from collections.abc import Sequence

from tutorial_atlas_control.cli.convention import (
    EXIT_INTERRUPTED,
    EXIT_REFUSED,
    add_bag_arguments,
    argument_type,
    check_bag_arguments,
    chosen_bag,
    print_error,
)
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.offline import (
    DEFAULT_TOLERANCE,
    ReplayError,
    format_report,
    replay_bag,
)
from tutorial_atlas_control.units import finite_number

PROG = 'replay_bag.py'
#: Exit status when the replay ran but deviates beyond the tolerance.
EXIT_DEVIATES = 3

DESCRIPTION = """\
Re-simulate a recorded Atlas run without ROS and report how far the replay strays from
the recording.

A bag with resets holds several tries (see analyze_bag.py): one try is replayed, by
default the last (--try N for another), from the reset it began with.

Starts from the simulator's reset (/atlas/sim_config last_reset_time; the torso pinned
for time_to_unpin), applies each step's recorded torque (/atlas/joint_states effort) with
MuJoCo's mj_step, and compares the joint positions and velocities with every recorded
joint state and the pelvis pose with /ground_truth_odom. Steps before the recorder
started are re-created with the simulator's own Stand-mode controller (the gains of
config/atlas_controller.yaml). With the same model and MuJoCo build the replay is exact
(all deviations 0). A scored run's /vrc_score is scored again and compared row for row.
"""

EPILOG = """\
JSON keys (--json): bag, sim_config {recorded, model_file, model_sha1, timestep (s),
time_to_unpin (s), last_reset_time (s)}, resets_in_bag, try (the try replayed, from 1),
tries (how many the bag holds), model_sha1_matches (bool or null),
start_time, end_time (s of sim time), reconstructed_steps, recorded_steps,
joint_position and joint_velocity {max (rad, rad/s), time (s), joint, samples},
pelvis_position {max (m), time, samples}, pelvis_orientation {max (rad), time, samples}
(null without /ground_truth_odom), tolerance, reproduced (bool), vrc_score
{recorded_rows, replayed_rows, completion, falls, first_difference (text or null)} (null
for an unscored run or a replay from a reset), warnings [text].

Exit status: 0 when every deviation is within --tolerance, 3 when the replay deviates,
1 when the bag cannot be read or replayed (missing topics, no /atlas/sim_config without
--assume-defaults, no such try, a recording that starts after a mid-run reset), 2 on bad
arguments (e.g. a --tolerance that is not a number >= 0).

Without BAG (or with --latest), the newest .bag in atlas.launch's bag directory
($TAC_BAG_DIR, else ~/.ros/tutorial_atlas_control/bags) is replayed.

Example: rosrun tutorial_atlas_control replay_bag.py --latest
         rosrun tutorial_atlas_control replay_bag.py atlas_2026-11-24-19-30-00.bag --try 2
"""


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (its --help is the documentation)."""
    parser = argparse.ArgumentParser(prog=PROG, description=DESCRIPTION, epilog=EPILOG,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    add_bag_arguments(parser, 'replay')
    parser.add_argument('--try', dest='try_number', metavar='N', type=int,
                        help='the try to replay, from 1 (-1: the last, the default)')
    parser.add_argument('--json', action='store_true', help='print one JSON object instead')
    parser.add_argument('--assume-defaults', action='store_true',
                        help='replay a bag without /atlas/sim_config (not recorded by '
                             'atlas.launch) as if pinned for 1 s after t = 0 (otherwise '
                             'refused: exit 1)')
    parser.add_argument('--tolerance', type=argument_type(_tolerance), default=DEFAULT_TOLERANCE,
                        help='largest deviation (rad, rad/s, m) that still counts as '
                             'reproduced (default: %(default)g)')
    return parser


def _tolerance(text: str) -> float:
    tolerance = finite_number(text, allow_text=True)
    if tolerance is None or tolerance < 0.0:
        raise ReplayError(f'{text!r} is not a number >= 0')
    return tolerance


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    check_bag_arguments(parser, args)
    try:
        result = replay_bag(chosen_bag(args, 'replaying'), args.tolerance, args.try_number,
                            args.assume_defaults)
    except AtlasControlError as err:
        print_error(PROG, err)
        return EXIT_REFUSED
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    print(json.dumps(result.to_dict(), indent=2) if args.json else format_report(result))
    return 0 if result.reproduced else EXIT_DEVIATES
