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
import threading
import time
from collections.abc import Sequence

import rosgraph
import rospy
from atlas_msgs.msg import (
    AtlasBehaviorStepData,
    AtlasSimInterfaceCommand,
    AtlasSimInterfaceState,
)

from tutorial_atlas_control import topics
from tutorial_atlas_control.asi import (
    Behavior,
    Outcome,
    WalkClient,
    refusal_hint,
    yaw_of_quaternion,
)
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
    wrap_angle,
)

PROG = 'walk_client.py'
#: How long (s, wall time) to wait for the first state, and for the simulator to subscribe.
CONNECT_TIMEOUT_S = 30.0
#: Steps per turn of --circle.
STEPS_PER_TURN = 60
#: How long (s, wall time) to wait for the other subscribers the master lists (a recorder).
LISTED_CONNECT_TIMEOUT_S = 2.0
#: The walk is given up when no state came for this long (s, wall time): the simulator
#: stopped, died or was paused.
STATE_SILENCE_S = 2.0
#: How long (s, wall time) the STAND sent from the start's hold may take to be reported.
STAND_TIMEOUT_S = 10.0


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
    try:
        return _walk(plan, args)
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    except _Refused as err:
        print_error(PROG, err)
        return EXIT_REFUSED


class _Refused(Exception):
    """No master, no simulator, or a walk that did not end well."""


def _walk(plan: list[Footstep], args: argparse.Namespace) -> int:
    uri = rosgraph.get_master_uri()
    if not rosgraph.is_master_online(uri):
        raise _Refused(f'no ROS master at {uri}: start the simulator first')
    rospy.init_node('walk_client', anonymous=True, disable_signals=True)
    try:
        first = rospy.wait_for_message(topics.ASI_STATE, AtlasSimInterfaceState,
                                       timeout=CONNECT_TIMEOUT_S)
    except rospy.ROSException:
        raise _Refused(f'no {topics.ASI_STATE} within {CONNECT_TIMEOUT_S:.0f} s: is the '
                       'simulator running?') from None
    feet = first.foot_pos_est
    left_yaw, right_yaw = (yaw_of_quaternion(o.x, o.y, o.z, o.w)
                           for o in (foot.orientation for foot in feet))
    yaw = left_yaw + 0.5 * wrap_angle(right_yaw - left_yaw)
    origin = (0.5 * (feet[0].position.x + feet[1].position.x),
              0.5 * (feet[0].position.y + feet[1].position.y))
    client = WalkClient(placed(plan, origin, yaw), streaming=not args.once)
    publisher = rospy.Publisher(topics.ASI_COMMAND, AtlasSimInterfaceCommand, queue_size=1,
                                tcp_nodelay=True)
    ended = threading.Event()
    last: list[AtlasSimInterfaceState] = [first]

    def on_state(state: AtlasSimInterfaceState) -> None:
        if ended.is_set():  # given up, interrupted or walked: the client answers no more
            return
        last[0] = state
        steps = client.on_state(state.current_behavior, state.behavior_feedback.status_flags,
                                state.walk_feedback.current_step_index,
                                state.walk_feedback.next_step_index_needed)
        if client.outcome is not None:
            ended.set()
        elif steps is not None:
            _send(publisher, _command(steps), ended)

    _wait_for_subscribers(publisher)
    if first.current_behavior == Behavior.USER:
        _stand_first(publisher, len(plan))
    heard = [time.monotonic()]

    def on_heard(state: AtlasSimInterfaceState) -> None:
        heard[0] = time.monotonic()
        on_state(state)

    rospy.Subscriber(topics.ASI_STATE, AtlasSimInterfaceState, on_heard, queue_size=1,
                     tcp_nodelay=True)
    _wait_for_the_end(ended, heard, client, args.timeout)
    state = last[0]
    feet = ', '.join(f'({foot.position.x:.3f}, {foot.position.y:.3f})'
                     for foot in state.foot_pos_est)
    if client.outcome is not Outcome.WALKED:
        hint = refusal_hint(state.behavior_feedback.status_flags, state.current_behavior)
        raise _Refused(f'the walk {client.outcome.value} after {client.steps_taken} of '
                       f'{len(plan)} steps ({hint})')
    print(f'{PROG}: walked {client.steps_taken} of {len(plan)} steps '
          f'({"once" if args.once else "streamed"}), back in Stand; feet at {feet}')
    rospy.signal_shutdown('walked')
    return 0


def _wait_for_subscribers(publisher: rospy.Publisher) -> None:
    """Until the simulator is subscribed to the commands, and (for a while) every other
    subscriber the master lists: a recorder connected before the first commands go gets
    them (the only ones that carry the first steps)."""
    deadline = rospy.get_time() + CONNECT_TIMEOUT_S
    while publisher.get_num_connections() == 0:
        if rospy.get_time() > deadline or rospy.is_shutdown():
            raise _Refused(f'the simulator did not subscribe to {topics.ASI_COMMAND}')
        rospy.sleep(0.01)
    deadline = rospy.get_time() + LISTED_CONNECT_TIMEOUT_S
    while publisher.get_num_connections() < _listed_subscribers(topics.ASI_COMMAND) \
            and rospy.get_time() < deadline and not rospy.is_shutdown():
        rospy.sleep(0.01)


def _send(publisher: rospy.Publisher, command: AtlasSimInterfaceCommand,
          ended: threading.Event) -> None:
    """Publish from the state callback; a state read just as the client stopped (rospy
    closing its topics on the way out) sends nothing and says nothing."""
    try:
        publisher.publish(command)
    except rospy.ROSException:
        if not ended.is_set():
            raise


def _wait_for_the_end(ended: threading.Event, heard: list[float], client: WalkClient,
                      timeout_s: float) -> None:
    """Until the walk ends; _Refused when the states stop for STATE_SILENCE_S or at the
    timeout; Ctrl-C says how many steps were taken."""
    planned = len(client.plan)
    deadline = time.monotonic() + timeout_s
    try:
        _wait_or_give_up(ended, heard, client, deadline, timeout_s)
    except KeyboardInterrupt:
        print(f'{PROG}: interrupted after {client.steps_taken} of {planned} steps',
              file=sys.stderr)
        raise
    finally:
        ended.set()  # however it ended, the state callback sends nothing more


def _wait_or_give_up(ended: threading.Event, heard: list[float], client: WalkClient,
                     deadline: float, timeout_s: float) -> None:
    planned = len(client.plan)
    while not ended.wait(0.05):
        now = time.monotonic()
        if now - heard[0] > STATE_SILENCE_S:
            raise _Refused(f'no {topics.ASI_STATE} for {STATE_SILENCE_S:g} s: the '
                           'simulator stopped or is paused '
                           f'({client.steps_taken} of {planned} steps taken)')
        if now > deadline:
            raise _Refused(f'the walk did not end within {timeout_s:g} s '
                           f'({client.steps_taken} of {planned} steps taken)')


def _stand_first(publisher: rospy.Publisher, planned: int) -> None:
    """The start's hold (User): STAND, then wait until the state says Stand."""
    print(f'{PROG}: the robot is in User (the tutorial\'s hold): sending STAND first',
          flush=True)
    command = AtlasSimInterfaceCommand()
    command.header.stamp = rospy.Time.now()
    command.behavior = Behavior.STAND
    publisher.publish(command)
    try:
        state = rospy.wait_for_message(topics.ASI_STATE, AtlasSimInterfaceState,
                                       timeout=CONNECT_TIMEOUT_S)
        deadline = time.monotonic() + STAND_TIMEOUT_S
        while state.current_behavior != Behavior.STAND:
            if time.monotonic() > deadline:
                hint = refusal_hint(state.behavior_feedback.status_flags,
                                    state.current_behavior)
                raise _Refused(f'STAND was not taken within {STAND_TIMEOUT_S:g} s ({hint}); '
                               f'0 of {planned} steps taken')
            state = rospy.wait_for_message(topics.ASI_STATE, AtlasSimInterfaceState,
                                           timeout=CONNECT_TIMEOUT_S)
    except rospy.ROSException:
        raise _Refused(f'no {topics.ASI_STATE} after STAND: is the simulator running?') from None


def _listed_subscribers(topic: str) -> int:
    """How many nodes the master lists as subscribers of `topic` (0 if it cannot say)."""
    try:
        _, subscribers, _ = rosgraph.Master(rospy.get_name()).getSystemState()
    except (rosgraph.MasterException, OSError):
        return 0
    return next((len(nodes) for name, nodes in subscribers if name == topic), 0)


def step_message(step: Footstep) -> AtlasBehaviorStepData:
    """A footstep as atlas_msgs/AtlasBehaviorStepData (x, y, yaw; z and swing height 0)."""
    data = AtlasBehaviorStepData(step_index=step.step_index, foot_index=step.foot_index,
                                 duration=step.duration_s)
    data.pose.position.x, data.pose.position.y = step.x_m, step.y_m
    half = 0.5 * step.yaw_rad
    data.pose.orientation.z, data.pose.orientation.w = math.sin(half), math.cos(half)
    return data


def _command(steps: list[Footstep]) -> AtlasSimInterfaceCommand:
    """An AtlasSimInterfaceCommand WALK of `steps` (empty slots after them)."""
    command = AtlasSimInterfaceCommand()
    command.behavior = command.WALK
    for slot, step in enumerate(steps[:len(command.walk_params.step_queue)]):
        command.walk_params.step_queue[slot] = step_message(step)
    return command
