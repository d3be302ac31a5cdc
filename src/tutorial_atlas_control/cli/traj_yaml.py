"""Command line of traj_yaml.py: the DRCSim tutorial's trajectory player.

It keeps the tutorial's command line rather than argparse's: its usage text, exit status
1 for every refusal, and its messages (the file and the master are checked before the
node starts). Ctrl-C before the node starts exits 130; once it runs, rospy's own SIGINT
handling ends the trajectory as the tutorial's did (exit 1).
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

import rospy

from tutorial_atlas_control.cli.convention import EXIT_INTERRUPTED
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.node.traj_yaml import (
    NODE_NAME,
    joint_commands_type,
    play,
    require_master,
)
from tutorial_atlas_control.trajectories.trajectory import load_trajectory, locate_trajectory_file

#: The tutorial's exit status for every refusal and failure.
EXIT_FAILED = 1

USAGE = ('usage: traj_yaml.py YAML_FILE TRAJECTORY_NAME\n'
         ' where TRAJECTORY is a dictionary defined in YAML_FILE')
DESCRIPTION = (
    'Play trajectory TRAJECTORY_NAME of YAML_FILE on the simulated Atlas: for each waypoint\n'
    '[duration_s, "28 joint positions"], move every joint linearly from its measured position\n'
    'to the waypoint over duration_s, publishing osrf_msgs/JointCommands on '
    '/atlas/joint_commands\n'
    'at 50 Hz with the gains atlas_controller/gains/<joint>/{p,i,d,i_clamp}.\n'
    'A YAML_FILE name not found from the current directory is taken from the package\'s\n'
    'trajectories/ folder (as the tutorial, run from the folder holding Traj_data2.yaml).\n'
    'Start the simulator first:\n'
    '  roslaunch tutorial_atlas_control atlas.launch\n'
    'ROS remapping arguments (name:=value) are accepted; ~joint_state_timeout (s, default 10)\n'
    'sets how long to wait for the first joint state, ~subscriber_timeout (s, default 10) how\n'
    'long to wait for the simulator to subscribe to the commands.'
)
HELP_OPTIONS = ('-h', '--help')




def main(argv: Sequence[str] | None = None) -> int:
    """Run ``traj_yaml.py YAML_FILE TRAJECTORY_NAME``; return the exit status.

    Args:
        argv: the arguments after the program name (default ``sys.argv[1:]``);
            ROS remapping arguments are removed with ``rospy.myargv``.
    """
    raw = list(sys.argv[1:] if argv is None else argv)
    args = rospy.myargv(raw)
    if any(arg in HELP_OPTIONS for arg in args):
        print(f'{USAGE}\n\n{DESCRIPTION}')
        return 0
    if len(args) != 2:
        print(USAGE, file=sys.stderr)
        return EXIT_FAILED
    try:
        return _run(*args, raw)
    except KeyboardInterrupt:  # before init_node: rospy has no SIGINT handler yet
        return EXIT_INTERRUPTED


def _run(path: str, name: str, raw: list[str]) -> int:
    """Check the file and the master, start the node and play; the exit status."""
    try:
        path = locate_trajectory_file(path, announce=print)
        waypoints = load_trajectory(path, name)
        message_type = joint_commands_type()
        require_master()
    except AtlasControlError as err:
        print(err, file=sys.stderr)
        return EXIT_FAILED

    try:
        rospy.init_node(NODE_NAME, argv=[sys.argv[0], *raw])
    except rospy.ROSInitException as err:
        print(f'cannot start ROS node {NODE_NAME}: {err}', file=sys.stderr)
        return EXIT_FAILED
    try:
        play(waypoints, message_type, path, name)
    except AtlasControlError as err:
        rospy.logerr(str(err))
        return EXIT_FAILED
    except rospy.ROSTimeMovedBackwardsException:
        rospy.logerr('ROS time moved backwards (was the simulation reset?); trajectory aborted')
        return EXIT_FAILED
    except rospy.ROSInterruptException:
        rospy.logwarn('shut down before the trajectory finished')
        return EXIT_FAILED
    return 0
