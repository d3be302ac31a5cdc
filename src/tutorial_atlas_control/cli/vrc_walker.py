"""Command line of vrc_walker.py: a DRC-era course walker for the VRC's Task 2.

It walks the course gate to gate through the AtlasSimInterface, as a VRC team's client did:
the legs from the nearest gate still ahead of the robot to --to (course/legs.py), each
planned from where the feet are (foot_pos_est) once Stand has held a second after the last
one, and streamed as WALK
commands (the window from next_step_index_needed on every state). Steps land where the
course's ground is (the simulator puts each on the surface under it). It prints each gate
passed and every other event of /vrc_score, then the score. It ends with exit 0 once
--to is passed with no fall, 1 on a fall, a refused walk, a walk that did not end or a gate
not passed, 130 on Ctrl-C. With --terrain laser each leg is planned on the head laser's
height map of what it has seen (the spindle spinning; cli/laser_listener.py) instead of the
course's description, and the map's figures at the chosen footsteps are printed.
"""

from __future__ import annotations

import argparse
import sys
import threading
import time
from collections.abc import Sequence

import numpy as np
import rospy
from atlas_msgs.msg import VRCScore

from tutorial_atlas_control import topics
from tutorial_atlas_control.asi import Behavior, Outcome, WalkClient, refusal_hint
from tutorial_atlas_control.cli.asi_link import AsiLink, Refused
from tutorial_atlas_control.cli.convention import (
    EXIT_INTERRUPTED,
    EXIT_REFUSED,
    positive_number,
    print_error,
)
from tutorial_atlas_control.cli.laser_listener import LaserListener, half_turn_scans
from tutorial_atlas_control.course import (
    BLOCKS,
    GATES,
    LEG_PAUSE_S,
    CourseError,
    Leg,
    course_height_m,
    legs_ahead,
)
from tutorial_atlas_control.offline import (
    MAX_LOOKS,
    PLANNING_GROUNDS,
    SPIN_RAD_S,
    PlanningGround,
    footstep_errors,
    leg_plan,
    level_footstep,
    resumed_leg,
    seen_prefix,
)
from tutorial_atlas_control.walking import Footstep, RouteGait, WalkingError

PROG = 'vrc_walker.py'
#: How long (s, wall time) /vrc_score may take to report a gate the walk has passed.
SCORE_WAIT_S = 5.0
#: How long (s, wall time) the first look around (half a spindle turn) may take.
LOOK_TIMEOUT_S = 60.0


def _parser() -> argparse.ArgumentParser:
    gates = [gate.name for gate in GATES]
    parser = argparse.ArgumentParser(
        prog=PROG, description=__doc__.split('\n\n')[1].replace('\n', ' '),
        epilog='Start the course first: roslaunch tutorial_atlas_control vrc_task_2.launch '
               '(or one of its start variants, vrc_task_2_mud_start.launch, ...)')
    parser.add_argument('--to', choices=gates, default=gates[-1], metavar='GATE',
                        help=f'the last gate to pass ({", ".join(gates)}; default '
                             '%(default)s: the whole course)')
    parser.add_argument('--stride', type=positive_number, default=RouteGait.stride_m,
                        metavar='M', help='longest stride (m, default %(default)g)')
    parser.add_argument('--terrain', choices=PLANNING_GROUNDS, default='world',
                        help="the ground each leg is planned on: the course's description, or "
                        "the head laser's height map of what it has seen (default %(default)s)")
    parser.add_argument('--timeout', type=positive_number, default=900.0, metavar='S',
                        help='give up after this long (s, wall time; default %(default)g)')
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of scripts/vrc_walker.py (`argv` without the program name)."""
    parser = _parser()
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    try:
        gait = RouteGait(stride_m=args.stride)
    except WalkingError as err:
        parser.error(str(err))
    link = AsiLink(PROG)
    try:
        return _walk_course(link, args.to, gait, args.timeout, args.terrain == 'laser')
    except KeyboardInterrupt:
        print(f'{PROG}: interrupted', file=sys.stderr)
        return EXIT_INTERRUPTED
    except Refused as err:
        print_error(PROG, err)
        return EXIT_REFUSED


class _ScoreWatch:
    """/vrc_score's messages as they come: each event printed, the last kept."""

    def __init__(self) -> None:
        self.last: VRCScore | None = None
        self.events: list[str] = []
        self._changed = threading.Condition()

    def on_score(self, score: VRCScore) -> None:
        with self._changed:
            self.last = score
            if score.message.strip():
                elapsed = score.sim_time_elapsed.to_sec()
                print(f'{PROG}: /vrc_score at {score.sim_time.to_sec():.2f} s (course clock '
                      f'{elapsed:.2f} s): {score.message.strip()}', flush=True)
                self.events.append(score.message)
            self._changed.notify_all()

    def passed(self, gate: str) -> bool:
        number = [known.name for known in GATES].index(gate) + 1
        return any(f'passed through gate {number}.' in event for event in self.events)

    def wait_for(self, gate: str, timeout_s: float) -> bool:
        """Whether `gate` was reported passed within `timeout_s` (wall time)."""
        with self._changed:
            return self._changed.wait_for(lambda: self.passed(gate), timeout_s)


def _walk_course(link: AsiLink, to_gate: str, gait: RouteGait, timeout_s: float,
                 laser: bool) -> int:
    score = _ScoreWatch()
    first = link.connect('vrc_walker')
    listener = LaserListener(SPIN_RAD_S) if laser else None
    rospy.Subscriber(topics.VRC_SCORE, VRCScore, score.on_score, queue_size=100)
    pelvis = first.pos_est.position
    legs = legs_ahead(pelvis.x, pelvis.y, to_gate)
    if not legs:
        raise Refused(f'{to_gate} is behind the robot at ({pelvis.x:.2f}, {pelvis.y:.2f})')
    print(f'{PROG}: from ({pelvis.x:.2f}, {pelvis.y:.2f}): '
          f'{", ".join(leg.gate for leg in legs)}', flush=True)
    if first.current_behavior == Behavior.USER:
        link.stand_first()
    if listener is not None and not listener.wait_for_scans(half_turn_scans(SPIN_RAD_S),
                                                            LOOK_TIMEOUT_S):
        raise Refused(f'no half turn of laser scans within {LOOK_TIMEOUT_S:g} s '
                      f'({listener.scans} placed, {listener.dropped} without /tf)')
    deadline = time.monotonic() + timeout_s
    for number, leg in enumerate(legs):
        if number > 0:
            link.hold(LEG_PAUSE_S)
        _walk_leg(link, leg, gait, deadline - time.monotonic(), listener)
    passed = score.wait_for(to_gate, SCORE_WAIT_S)
    last = score.last
    if last is not None:
        print(f'{PROG}: score: completion {last.completion_score} of 4, falls {last.falls}, '
              f'course clock {last.sim_time_elapsed.to_sec():.2f} s', flush=True)
    link.close('walked')
    if last is not None and last.falls > 0:
        raise Refused(f'/vrc_score counts {last.falls} fall(s)')
    if not passed:
        raise Refused(f'the walk ended but /vrc_score did not report {to_gate} passed')
    return 0


def _walk_leg(link: AsiLink, leg: Leg, gait: RouteGait, timeout_s: float,
              listener: LaserListener | None) -> None:
    """One leg, planned from where the feet are now (on the course's description or the
    laser's map), streamed to its end; on the map, only as far as it has seen, then,
    having stood LEG_PAUSE_S looking, the rest planned again (offline.seen_prefix)."""
    deadline = time.monotonic() + timeout_s
    began, _ = link.feet()
    for look in range(MAX_LOOKS):
        if look:
            link.hold(LEG_PAUSE_S)
        if deadline <= time.monotonic():
            raise Refused(f'no time left for the leg to {leg.gate}')
        rest, again = resumed_leg(leg, gait, began, link.feet()[0]) if look else (leg, gait)
        plan, walked = _plan_leg(link, rest, again, listener)
        client = WalkClient(plan[:walked], streaming=True)
        link.walk(client, deadline - time.monotonic())
        if client.outcome is not Outcome.WALKED:
            state = link.last
            assert state is not None  # connected
            hint = refusal_hint(state.behavior_feedback.status_flags, state.current_behavior)
            raise Refused(f'the walk to {leg.gate} {client.outcome.value} after '
                          f'{client.steps_taken} of {walked} steps ({hint})')
        if walked == len(plan):
            return


def _plan_leg(link: AsiLink, leg: Leg, gait: RouteGait,
              listener: LaserListener | None) -> tuple[list[Footstep], int]:
    """The leg's steps from where the feet are, and how many to walk before looking again."""
    origin, heading = link.feet()
    try:
        if listener is None:
            plan = leg_plan(leg, origin, heading, gait, BLOCKS, course_height_m)
            walked = len(plan)
        else:
            seen = listener.snapshot()
            ground = PlanningGround(seen)
            plan = leg_plan(leg, origin, heading, gait, (), ground, seen.grid.obstacle_xy())
            _print_map_figures(leg, plan, ground)
            walked = seen_prefix(plan, seen, level_footstep(ground))
    except (WalkingError, CourseError, ValueError) as err:
        raise Refused(f'no route to {leg.gate} from ({origin[0]:.2f}, {origin[1]:.2f}): '
                      f'{err}') from None
    then = '' if walked == len(plan) else f', walking {walked} before looking again'
    print(f'{PROG}: to {leg.gate} from ({origin[0]:.2f}, {origin[1]:.2f}): {len(plan)} steps'
          f'{then}', flush=True)
    return plan, walked


def _print_map_figures(leg: Leg, plan: list, ground: PlanningGround) -> None:
    """The laser map's figures for a leg planned on it: its points, the planner's fallbacks
    to the nearest seen ground, and its error at the chosen footsteps against the course's
    description (a measurement: the plan does not read the description)."""
    asked, fallbacks, farthest = ground.asked, ground.fallbacks, ground.farthest_m
    known, errors = footstep_errors(plan, ground)
    size = np.abs(errors) if len(errors) else np.zeros(1)
    print(f'{PROG}: laser map for {leg.gate}: {len(ground.map.points)} points; '
          f'{known} of {len(plan)} footsteps on seen ground, {fallbacks} of {asked} heights '
          f'the nearest seen (up to {farthest:.2f} m away); error at the footsteps '
          f'p50 {np.percentile(size, 50) * 100:.1f} cm, p95 {np.percentile(size, 95) * 100:.1f} '
          f'cm, max {size.max() * 100:.1f} cm', flush=True)
