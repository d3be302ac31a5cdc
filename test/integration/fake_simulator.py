#!/usr/bin/env python3
"""A stand-in simulator for traj_yaml.py's start-up: joint states now, commands later.

Publishes /atlas/joint_states (all 28 joints at 0 rad, 100 Hz of wall time) from the
start, and subscribes to /atlas/joint_commands only after --subscribe-after seconds
(never if negative): the start-up order that made the real simulator miss the first
commands on a starved host. Exits once it has --until-received commands, on SIGINT, or
after --run-for s; prints one JSON line when it exits: how many commands it received and
the positions of the first.
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import rospy
from osrf_msgs.msg import JointCommands
from sensor_msgs.msg import JointState

from tutorial_atlas_control.joints import JOINT_NAMES

#: How long it keeps listening after --until-received commands (s, wall).
LINGER_S = 1.0

def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument('--subscribe-after', type=float, required=True,
                        help='s of wall time; < 0: never')
    parser.add_argument('--run-for', type=float, required=True, help='s of wall time, then exit')
    parser.add_argument('--until-received', type=int, default=0,
                        help='exit LINGER_S after this many commands arrived '
                             '(0: run for --run-for)')
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node('fake_atlas_sim')
    received: list[JointCommands] = []
    publisher = rospy.Publisher('/atlas/joint_states', JointState, queue_size=10)
    state = JointState(name=list(JOINT_NAMES), position=[0.0] * len(JOINT_NAMES))
    started = time.monotonic()
    subscribed = False
    while not rospy.is_shutdown() and time.monotonic() - started < args.run_for:
        if 0 < args.until_received <= len(received):
            time.sleep(LINGER_S)  # a port sending too many would send the next within 20 ms
            break
        if not subscribed and 0 <= args.subscribe_after <= time.monotonic() - started:
            rospy.Subscriber('/atlas/joint_commands', JointCommands, received.append,
                             queue_size=1000)
            subscribed = True
        state.header.stamp = rospy.Time.now()
        publisher.publish(state)
        time.sleep(0.01)
    first = list(received[0].position) if received else None
    print(json.dumps({'received': len(received), 'first_position': first}), flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
