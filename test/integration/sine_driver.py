#!/usr/bin/env python3
"""Swings the left elbow (l_arm_elx, joint_states index 19) on a sine, in User mode.

    sine_driver.py --period S --duration S

Sends the tutorial's 28-joint JointCommands (standing pose, parameter-server gains) at
100 Hz of sim time, l_arm_elx at CENTER_RAD + AMPLITUDE_RAD * sin(2 pi t / period), for
--duration s of sim time (0: until SIGINT); switches to User after its first command.
The plot tests (test_plot_topics.py) plot that joint while it runs.
"""

from __future__ import annotations

import argparse
import math
import sys

import rospy
from osrf_msgs.msg import JointCommands
from std_msgs.msg import String

from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.trajectories.traj_yaml_node import build_command, read_gains

ELBOW = JOINT_NAMES.index('l_arm_elx')
#: The elbow's sine (rad): inside the joint's range, far from the standing 0.
CENTER_RAD = 1.0
AMPLITUDE_RAD = 0.5
RATE_HZ = 100.0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument('--period', type=float, required=True, help='s of sim time')
    parser.add_argument('--duration', type=float, default=0.0, help='s of sim time; 0: forever')
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node('sine_driver', anonymous=True, disable_signals=True)
    gains = read_gains()
    commands = rospy.Publisher('/atlas/joint_commands', JointCommands, queue_size=10)
    mode = rospy.Publisher('/atlas/control_mode', String, queue_size=1, latch=True)
    while commands.get_num_connections() == 0:
        rospy.sleep(0.05)
    start = rospy.Time.now()
    rate = rospy.Rate(RATE_HZ)
    switched = False
    try:
        while not rospy.is_shutdown():
            t = (rospy.Time.now() - start).to_sec()
            if args.duration and t > args.duration:
                break
            position = [0.0] * NUM_JOINTS
            position[ELBOW] = CENTER_RAD + AMPLITUDE_RAD * math.sin(2.0 * math.pi * t / args.period)
            commands.publish(build_command(JointCommands, position, gains, rospy.Time.now()))
            if not switched:
                mode.publish(String(data='User'))
                switched = True
            rate.sleep()
    except (KeyboardInterrupt, rospy.ROSInterruptException):
        pass
    return 0


if __name__ == '__main__':
    sys.exit(main())
