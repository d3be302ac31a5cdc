"""Command line of state_publisher.py: robot_state_publisher on the model's URDF (atlas.launch).

It keeps roslaunch's command line (MODEL_FILE and `name:=value` ROS arguments, usage from
sim/state_publisher_node.py's docstring) rather than argparse's.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from pathlib import Path

import mujoco

from tutorial_atlas_control.cli.convention import EXIT_INTERRUPTED, EXIT_REFUSED
from tutorial_atlas_control.node import refuse_if_running
from tutorial_atlas_control.sim import UrdfError, matching_urdf
from tutorial_atlas_control.sim import state_publisher_node as state_publisher

PROG = 'state_publisher.py'
HELP_OPTIONS = ('-h', '--help')


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of scripts/state_publisher.py (`argv` with the program name first)."""
    argv = list(sys.argv if argv is None else argv)
    plain = [arg for arg in argv[1:] if ':=' not in arg]
    ros_args = [arg for arg in argv[1:] if ':=' in arg]
    if len(plain) != 1 or plain[0] in HELP_OPTIONS:
        asked = bool(plain) and plain[0] in HELP_OPTIONS
        print(state_publisher.__doc__.strip(), file=sys.stdout if asked else sys.stderr)
        return 0 if asked else EXIT_REFUSED
    if refuse_if_running(PROG, 'robot_state_publisher', argv, full=False):
        return EXIT_REFUSED
    try:
        return _start(Path(plain[0]), ros_args)
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED


def _start(model_file: Path, ros_args: list[str]) -> int:
    """Set /robot_description and become robot_state_publisher; the exit status otherwise."""
    try:
        model = mujoco.MjModel.from_xml_path(str(model_file))
        _path, description = matching_urdf(model_file, model)
    except (ValueError, UrdfError) as err:
        print(f'{PROG}: robot_state_publisher not started: {err}', file=sys.stdout)
        return 0
    try:
        executable = state_publisher.robot_state_publisher_executable()
        state_publisher.set_robot_description(description)
    except (state_publisher.StatePublisherError, OSError) as err:
        print(f'{PROG}: {err}', file=sys.stderr)
        return EXIT_REFUSED
    sys.stdout.flush()
    os.execv(executable, [executable, *ros_args])
    return EXIT_REFUSED  # not reached
