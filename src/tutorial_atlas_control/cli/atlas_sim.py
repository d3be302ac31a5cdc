"""Command line of sim/atlas_sim_node.py, the simulator node that atlas.launch starts.

`--help` prints the node's parameters (node/sim_node.py's docstring). Like any ROS node it
exits 0 when ROS shuts it down (Ctrl-C, `rosnode kill`, another atlas_sim registering on the
same master: then with one line saying so), 1 when its set-up is refused, or when an
atlas_sim already runs on the master (node/single_instance.py: checked before registering,
so the first launch and its master go on).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from pathlib import Path

import rosgraph
import rospy

from tutorial_atlas_control import topics
from tutorial_atlas_control.cli.convention import EXIT_REFUSED
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.launch_args import unknown_arg_lines
from tutorial_atlas_control.node import follow_own_clock, refuse_if_running, sim_node
from tutorial_atlas_control.node.sim_node import NODE_NAME, build_node
from tutorial_atlas_control.processes import PACKAGE
from tutorial_atlas_control.resources import package_path
from tutorial_atlas_control.sim import start_line

HELP_OPTIONS = ('-h', '--help')
#: What the master gives as the reason when another node registers under our name.
SAME_NAME_REASON = 'new node registered with same name'


class ShutdownReason:
    """Remembers why rospy shut the node down (a pre-shutdown hook gets the reason)."""

    def __init__(self) -> None:
        self.text = ''

    def __call__(self, reason: str) -> None:
        self.text = str(reason)

    def taken_over(self) -> bool:
        return SAME_NAME_REASON in self.text


def took_over_line(name: str, master_uri: str) -> str:
    """The one line of a simulator that another one replaced."""
    return (f'{NODE_NAME}: another {NODE_NAME} took over: a second simulator registered as '
            f'{name} on {master_uri}, so this one stops (its launch and recording end); run '
            'one atlas.launch per master, or give the second its own (roslaunch -p PORT)')


def _package_launch_file(package: str, name: str) -> Path | None:
    path = package_path('launch', name)
    return path if package == PACKAGE and path.is_file() else None


def unknown_launch_arg_lines(parent_pid: int) -> list[str]:
    """launch_args' warnings when roslaunch (the parent) was given arguments no launch file
    of its command line declares; [] for any other parent."""
    try:
        raw = (Path('/proc') / str(parent_pid) / 'cmdline').read_bytes()
    except OSError:
        return []
    argv = [part.decode(errors='replace') for part in raw.split(b'\0') if part]
    if not any(Path(part).name == 'roslaunch' for part in argv[:2]):
        return []
    return unknown_arg_lines(argv, _package_launch_file)


def main(argv: Sequence[str] | None = None) -> int:
    """Start the node and step until ROS shuts it down; the exit status."""
    full_argv = list(argv) if argv is not None else list(sys.argv)
    args = rospy.myargv(full_argv)
    if any(arg in HELP_OPTIONS for arg in args[1:]):
        print(sim_node.__doc__)
        return 0
    if refuse_if_running(NODE_NAME, NODE_NAME, full_argv):
        return EXIT_REFUSED
    rospy.init_node(NODE_NAME)
    reason = ShutdownReason()
    rospy.core.add_preshutdown_hook(reason)
    try:
        node = build_node()
    except AtlasControlError as err:
        rospy.logfatal(f'{NODE_NAME}: {err}')
        return EXIT_REFUSED
    # Its own /clock is not received back (node/own_clock.py).
    follow_own_clock(node.loop.outbox, node.publishers[topics.CLOCK])
    rospy.loginfo(f'Atlas v1 simulator ready: dt={node.sim.dt_s * 1000:.1f} ms, '
                  f'real_time_factor={node.loop.real_time_factor}, paused={node.loop.paused}, '
                  f'torso pinned for {node.sim.time_to_unpin_s} s')
    if node.sim.start is not None:
        rospy.loginfo(start_line(node.sim.start, node.sim.start_qpos))
    for line in unknown_launch_arg_lines(os.getppid()):
        rospy.logwarn(line)
    status = node.spin()
    if reason.taken_over():
        print(took_over_line(rospy.get_name(), rosgraph.get_master_uri().rstrip('/')),
              file=sys.stderr)
    return status
