#!/usr/bin/env python3
"""Prints the positions of every /atlas/joint_commands message, one line each.

A stand-in for `rostopic echo /atlas/joint_commands/position` that subscribes at once:
rostopic echo waits until someone publishes the topic to learn its type, so that "nothing
was published" could not be checked against a subscription made beforehand.
"""

from __future__ import annotations

import sys

import rospy
from osrf_msgs.msg import JointCommands

#: The node's name: the tests look for its subscription on the master.
NODE_NAME = 'command_listener'


def main() -> int:
    rospy.init_node(NODE_NAME)

    def heard(message: JointCommands) -> None:
        print(list(message.position), flush=True)

    rospy.Subscriber('/atlas/joint_commands', JointCommands, heard, queue_size=1000)
    rospy.spin()  # until SIGINT
    return 0


if __name__ == '__main__':
    sys.exit(main())
