"""Command line of walk_client.py: a DRC-era walking client of the AtlasSimInterface.

It reads where the feet are from the first /atlas/atlas_sim_interface_state, lays a plan of
footsteps from there (straight ahead, or round a circle on the left), and sends WALK
commands as DRCSim's walking clients did: streamed, a new WALK with the window
[next_step_index_needed, +3] on every state message (1 kHz), or the first four steps once
(--once). From the default start (the tutorial's hold, which the interface reports as User)
it sends a STAND first, and says so. It ends when the walk has returned to Stand (exit 0),
or on a fall, a refused request, states that stop coming for STATE_SILENCE_S or the timeout
(exit 1); Ctrl-C says how many steps were taken (exit 130).
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Sequence

from tutorial_atlas_control.asi import Behavior, Outcome, WalkClient, refusal_hint
from tutorial_atlas_control.cli.asi_link import AsiLink, Refused
from tutorial_atlas_control.cli.convention import (
    EXIT_INTERRUPTED,
    EXIT_REFUSED,
    print_error,
    whole_number,
)
from tutorial_atlas_control.walking import (
    STEP_DURATION_S,
    Footstep,
    circle_steps,
    placed,
    straight_steps,
)

PROG = 'walk_client.py'
#: Steps per turn of --circle.
STEPS_PER_TURN = 60


def _positive(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'{text!r} is not a number') from None
    if not math.isfinite(value) or value <= 0.0:
        raise argparse.ArgumentTypeError(f'{text!r} must be a positive number')
    return value


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROG, description=__doc__.split('\n\n')[1].replace('\n', ' '),
        epilog='Start the simulator first: roslaunch tutorial_atlas_control atlas.launch '
               '(the tutorial\'s hold: a STAND is sent first) or atlas.launch '
               'startup_mode:=bdi_stand (Stand from 2 s)')
    parser.add_argument('--steps', type=whole_number(1), default=6,
                        help='how many steps (default 6)')
    parser.add_argument('--stride', type=_positive, default=0.25, metavar='M',
                        help='each foot this far ahead of the other (m, default 0.25)')
    parser.add_argument('--width', type=_positive, default=0.24, metavar='M',
                        help='the feet this far apart (m, default 0.24)')
    parser.add_argument('--duration', type=_positive, default=STEP_DURATION_S, metavar='S',
                        help=f'each step\'s duration (s, default {STEP_DURATION_S})')
    parser.add_argument('--circle', type=_positive, metavar='RADIUS',
                        help='walk round a circle of RADIUS (m) on the left, 60 steps a turn, '
                             'instead of straight ahead')
    parser.add_argument('--once', action='store_true',
                        help='send the first four steps once instead of streaming')
    parser.add_argument('--timeout', type=_positive, default=120.0, metavar='S',
                        help='give up after this long (s, wall time; default 120)')
    return parser


def plan_for(args: argparse.Namespace) -> list[Footstep]:
    """The plan from the origin facing +x (foot links' poses)."""
    if args.circle is not None:
        turns = math.ceil(args.steps / STEPS_PER_TURN)
        return circle_steps(args.circle, STEPS_PER_TURN, turns, args.width,
                            args.duration)[:args.steps]
    return straight_steps(args.steps, args.stride, args.width, args.duration)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of scripts/walk_client.py (`argv` without the program name)."""
    parser = _parser()
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    try:
        plan = plan_for(args)
    except ValueError as err:
        parser.error(str(err))
    link = AsiLink(PROG)
    try:
        return _walk(link, plan, args)
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    except Refused as err:
        print_error(PROG, err)
        return EXIT_REFUSED


def _walk(link: AsiLink, plan: list[Footstep], args: argparse.Namespace) -> int:
    first = link.connect('walk_client')
    origin, yaw = link.feet()
    client = WalkClient(placed(plan, origin, yaw), streaming=not args.once)
    if first.current_behavior == Behavior.USER:
        link.stand_first(len(plan))
    try:
        link.walk(client, args.timeout)
    except KeyboardInterrupt:
        print(f'{PROG}: interrupted after {client.steps_taken} of {len(plan)} steps',
              file=sys.stderr)
        raise
    state = link.last
    assert state is not None  # connected
    feet = ', '.join(f'({foot.position.x:.3f}, {foot.position.y:.3f})'
                     for foot in state.foot_pos_est)
    if client.outcome is not Outcome.WALKED:
        hint = refusal_hint(state.behavior_feedback.status_flags, state.current_behavior)
        raise Refused(f'the walk {client.outcome.value} after {client.steps_taken} of '
                      f'{len(plan)} steps ({hint})')
    print(f'{PROG}: walked {client.steps_taken} of {len(plan)} steps '
          f'({"once" if args.once else "streamed"}), back in Stand; feet at {feet}')
    link.close('walked')
    return 0
