"""Command line of mode_switching_demo.py: DRCSim's mode-switching demo against the simulator.

It sends the demo's commands (asi/mode_switching.py) 2 s apart in sim time, from the
first AtlasSimInterface state on: the user's PID at zeros with kp_velocity 50, the
stand-prep pose, StandPrep, Stand, the neck and arms under the PID while Stand balances, a
four-step Walk sent once, every joint back to the PID. One line per command; exit 0 when
the robot stood through it, 1 on a fall, no simulator or states that stop coming.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Sequence

import rosgraph
import rospy
from atlas_msgs.msg import AtlasCommand, AtlasSimInterfaceCommand, AtlasSimInterfaceState

from tutorial_atlas_control import topics
from tutorial_atlas_control.asi import (
    AFTER_LAST_S,
    CUES,
    KP_VELOCITY,
    Behavior,
    cue_messages,
    yaw_of_quaternion,
)
from tutorial_atlas_control.cli.convention import (
    EXIT_INTERRUPTED,
    EXIT_REFUSED,
    non_negative_number,
    print_error,
)
from tutorial_atlas_control.sim import GainsError, fallen, gains_from_params

PROG = 'mode_switching_demo.py'
#: How long (s, wall time) to wait for the first state and for the simulator to subscribe.
CONNECT_TIMEOUT_S = 30.0
#: The demo is given up when no state came for this long (s, wall time).
STATE_SILENCE_S = 5.0
#: The first command goes this long (s of sim time) after the first state.
LEAD_S = 0.5


class _Refused(Exception):
    """No master, no simulator, a fall or a silence."""


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog=PROG, description=__doc__.split('\n\n')[1].replace('\n', ' '),
        epilog='Start the simulator first: roslaunch tutorial_atlas_control atlas.launch')
    parser.add_argument('--kp-velocity', type=non_negative_number, default=KP_VELOCITY,
                        metavar='GAIN',
                        help='the AtlasCommands\' velocity gain, N m s/rad (default: '
                             f'{KP_VELOCITY:g}, the demo\'s; 0 shows why it needs one)')
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of scripts/mode_switching_demo.py (`argv` without the program name)."""
    args = _parser().parse_args(sys.argv[1:] if argv is None else argv)
    try:
        return _run(args.kp_velocity)
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    except _Refused as err:
        print_error(PROG, err)
        return EXIT_REFUSED


def _run(kp_velocity: float) -> int:
    uri = rosgraph.get_master_uri()
    if not rosgraph.is_master_online(uri):
        raise _Refused(f'no ROS master at {uri}: start the simulator first')
    rospy.init_node('mode_switching_demo', anonymous=True, disable_signals=True)
    try:
        kp_position = gains_from_params(rospy.get_param(topics.GAINS_PARAM, {})).p
    except GainsError as err:
        raise _Refused(str(err)) from None
    publishers = {topics.ATLAS_COMMAND: rospy.Publisher(topics.ATLAS_COMMAND, AtlasCommand,
                                                        queue_size=10),
                  topics.ASI_COMMAND: rospy.Publisher(topics.ASI_COMMAND,
                                                      AtlasSimInterfaceCommand, queue_size=10)}
    latest: list[AtlasSimInterfaceState | None] = [None]
    heard = [time.monotonic()]

    def on_state(state: AtlasSimInterfaceState) -> None:
        latest[0], heard[0] = state, time.monotonic()

    rospy.Subscriber(topics.ASI_STATE_RECORDED, AtlasSimInterfaceState, on_state, queue_size=1)
    deadline = time.monotonic() + CONNECT_TIMEOUT_S
    while latest[0] is None or any(p.get_num_connections() == 0 for p in publishers.values()):
        if time.monotonic() > deadline:
            raise _Refused('no simulator: no AtlasSimInterface state, or no subscriber to '
                           'the commands, within 30 s')
        time.sleep(0.01)
    start_s = _sim_s(latest[0]) + LEAD_S
    lowest, walked_from = math.inf, None
    for cue in (*CUES, None):
        due_s = start_s + (CUES[-1].at_s + AFTER_LAST_S if cue is None else cue.at_s)
        while (state := latest[0]) is not None and _sim_s(state) < due_s:
            lowest = min(lowest, state.pos_est.position.z)
            if fallen(state.pos_est.position.z):  # a state holds no world: flat ground
                raise _Refused(f'the robot fell at sim time {_sim_s(state):.2f} s, '
                               + (f'before {cue.name} was sent' if cue else
                                  'after the last command'))
            if time.monotonic() - heard[0] > STATE_SILENCE_S:
                raise _Refused(f'no state for {STATE_SILENCE_S:g} s: the simulator stopped')
            time.sleep(0.002)
        if cue is None:
            break
        position = state.pos_est.position
        pose = (position.x, position.y, _heading(state))
        if cue.name == 'WALK':
            walked_from = (position.x, position.y)
        for topic, raw in cue_messages(cue, int(_sim_s(state) * 1e9), kp_position, pose,
                                       kp_velocity):
            message = publishers[topic].data_class()
            message.deserialize(raw)
            publishers[topic].publish(message)
        print(f'{PROG}: {_sim_s(state):7.2f} s  {cue.name}: pelvis {position.z:.3f} m, '
              f'behaviour {Behavior(state.current_behavior).name}', flush=True)
    end = latest[0].pos_est.position
    walked = math.hypot(end.x - walked_from[0], end.y - walked_from[1]) if walked_from else 0.0
    print(f'{PROG}: no fall (lowest pelvis {lowest:.3f} m); walked {walked:.2f} m; ended in '
          f'{Behavior(latest[0].current_behavior).name}')
    rospy.signal_shutdown('done')
    return 0


def _heading(state: AtlasSimInterfaceState) -> float:
    """The feet's mean yaw (rad): pos_est carries no orientation (DRCSim's demo took the
    IMU's)."""
    left, right = (yaw_of_quaternion(o.x, o.y, o.z, o.w)
                   for o in (foot.orientation for foot in state.foot_pos_est))
    return left + 0.5 * math.remainder(right - left, math.tau)


def _sim_s(state: AtlasSimInterfaceState) -> float:
    return state.header.stamp.to_sec()
