"""Command line of traj_yaml.py: the DRCSim tutorial's trajectory player.

It keeps the tutorial's command line rather than argparse's: its usage text, exit status
1 for every refusal, and its messages (the file and the master are checked before the
node starts). Ctrl-C exits 130, as in every script: before the node starts as a
KeyboardInterrupt, once it runs through rospy's own SIGINT handling, which ends the
trajectory (a shutdown for any other reason, such as `rosnode kill`, still exits 1).
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Callable, Sequence
from types import FrameType

import rospy

from tutorial_atlas_control.cli.convention import EXIT_INTERRUPTED
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.trajectories import load_trajectory, locate_trajectory_file
from tutorial_atlas_control.trajectories.traj_yaml_node import (
    NODE_NAME,
    joint_commands_type,
    play,
    require_master,
)

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
#: How long (s) a Ctrl-C'd port waits for rospy to unregister from the master.
SHUTDOWN_WAIT_S = 5.0


class _SigintSeen:
    """Chained in front of rospy's SIGINT handler, to tell Ctrl-C from other shutdowns.

    rospy's handler shuts the node down inside the signal handler, on the main thread; when
    the signal lands while that thread is in an XML-RPC call to the master (a log line's
    first /rosout parameter look-up), the shutdown waits for the lock that very call holds,
    forever. So the handler runs on a thread of its own, and the main thread sees the
    shutdown at its next command.
    """

    def __init__(self) -> None:
        self.seen = False
        self._rospy_handler: Callable[[int, FrameType | None], object] | int | None = None
        self._shutdown: threading.Thread | None = None

    def install(self) -> None:
        self._rospy_handler = signal.getsignal(signal.SIGINT)
        signal.signal(signal.SIGINT, self._handle)

    def _handle(self, signum: int, _frame: FrameType | None) -> None:
        self.seen = True
        handler = self._rospy_handler
        if not callable(handler):
            raise KeyboardInterrupt
        if self._shutdown is None:
            self._shutdown = threading.Thread(target=handler, args=(signum, None),
                                              name='sigint-shutdown', daemon=True)
            self._shutdown.start()

    def wait(self, timeout_s: float) -> None:
        """Let rospy's shutdown (unregistering from the master) finish before exiting."""
        if self._shutdown is not None:
            self._shutdown.join(timeout_s)


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
    sigint = _SigintSeen()
    sigint.install()
    try:
        play(waypoints, message_type, path, name)
    except AtlasControlError as err:
        rospy.logerr(str(err))
        return EXIT_FAILED
    except rospy.ROSTimeMovedBackwardsException:
        rospy.logerr('ROS time moved backwards (was the simulation reset?); trajectory aborted')
        return EXIT_FAILED
    except rospy.ROSException as err:
        # ROSInterruptException, or a publish() racing the shutdown thread that closed the
        # publisher ("publish() to a closed topic", seen with a busy core): both a shutdown.
        # rospy closes topics in its pre-shutdown hooks, before is_shutdown() turns true.
        if not (isinstance(err, rospy.ROSInterruptException)
                or rospy.core.is_shutdown_requested()):
            raise
        rospy.logwarn('shut down before the trajectory finished')
        return EXIT_INTERRUPTED if sigint.seen else EXIT_FAILED
    finally:
        sigint.wait(SHUTDOWN_WAIT_S)
    return EXIT_INTERRUPTED if sigint.seen else 0
