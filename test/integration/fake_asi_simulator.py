#!/usr/bin/env python3
"""A stand-in AtlasSimInterface for walk_client.py's lines: it publishes
/atlas/atlas_sim_interface_state at 200 Hz of wall time, the feet side by side, saying User
until it receives a STAND (then Stand, as the default start's library does), for --states-for
seconds; then it goes silent (still subscribed, as a paused or hung simulator) until
--run-for s or SIGINT. It prints one JSON line when it exits: the behaviours received.
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import rospy
from atlas_msgs.msg import AtlasSimInterfaceCommand, AtlasSimInterfaceState

USER, STAND = 1, 0
RATE_HZ = 200.0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument('--states-for', type=float, required=True)
    parser.add_argument('--run-for', type=float, required=True)
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node('atlas_sim', disable_signals=True)
    received: list[int] = []
    behavior = [USER]

    def on_command(command: AtlasSimInterfaceCommand) -> None:
        received.append(command.behavior)
        if command.behavior == STAND:
            behavior[0] = STAND

    rospy.Subscriber('/atlas/atlas_sim_interface_command', AtlasSimInterfaceCommand, on_command)
    publisher = rospy.Publisher('/atlas/atlas_sim_interface_state', AtlasSimInterfaceState,
                                queue_size=10)
    start = time.monotonic()
    try:
        while time.monotonic() - start < args.run_for:
            if time.monotonic() - start < args.states_for:
                state = AtlasSimInterfaceState()
                state.current_behavior = behavior[0]
                for foot, y in zip(state.foot_pos_est, (0.089, -0.089)):
                    foot.position.y, foot.orientation.w = y, 1.0
                state.pos_est.position.z = 0.9
                publisher.publish(state)
            time.sleep(1.0 / RATE_HZ)
    except KeyboardInterrupt:
        pass
    print(json.dumps({'received': sorted(set(received))}), flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
