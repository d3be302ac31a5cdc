"""Start Debian's robot_state_publisher on the simulated model's URDF (atlas.launch).

usage: state_publisher.py MODEL_FILE [ROS arguments]

Sets /robot_description to the URDF beside MODEL_FILE (urdf.matching_urdf) and then
becomes robot_state_publisher (exec, same ROS name, parameters and remappings), as DRCSim's
launch ran it. A model without a matching URDF gets no robot_state_publisher: this exits 0
quietly, and the simulator, which makes the same check, logs the one warning.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.topics import ROBOT_DESCRIPTION_PARAM

#: The Debian package and executable started.
RSP_PACKAGE = 'robot_state_publisher'
RSP_EXECUTABLE = 'robot_state_publisher'
NAME = 'state_publisher.py'


class StatePublisherError(AtlasControlError):
    """robot_state_publisher cannot be started; the message says what to install or fix."""


def robot_state_publisher_executable() -> str:
    """Path of robot_state_publisher (Debian: /usr/lib/robot_state_publisher/...).

    Raises:
        StatePublisherError: it is not installed.
    """
    import roslib.packages
    try:
        found = roslib.packages.find_node(RSP_PACKAGE, RSP_EXECUTABLE)
    except Exception:  # noqa: BLE001 - rospkg raises several kinds for a missing package
        found = []
    if not found:
        raise StatePublisherError('robot_state_publisher is not installed; run `make setup` '
                                  '(Debian package ros-robot-state-publisher).')
    return found[0]


def main(argv: list[str] | None = None) -> int:
    """Entry point of scripts/state_publisher.py."""
    argv = list(sys.argv if argv is None else argv)
    plain = [arg for arg in argv[1:] if ':=' not in arg]
    ros_args = [arg for arg in argv[1:] if ':=' in arg]
    if len(plain) != 1 or plain[0] in ('-h', '--help'):
        print(__doc__.strip(), file=sys.stdout if plain[:1] in (['-h'], ['--help']) else sys.stderr)
        return 0 if plain[:1] in (['-h'], ['--help']) else 1
    import mujoco
    import rosgraph

    from tutorial_atlas_control.sim.urdf import UrdfError, matching_urdf
    model_file = Path(plain[0])
    try:
        model = mujoco.MjModel.from_xml_path(str(model_file))
        _path, description = matching_urdf(model_file, model)
    except (ValueError, UrdfError) as err:
        print(f'{NAME}: robot_state_publisher not started: {err}', file=sys.stdout)
        return 0
    try:
        executable = robot_state_publisher_executable()
        rosgraph.Master('/state_publisher').setParam(ROBOT_DESCRIPTION_PARAM, description)
    except (StatePublisherError, OSError) as err:
        print(f'{NAME}: {err}', file=sys.stderr)
        return 1
    sys.stdout.flush()
    os.execv(executable, [executable, *ros_args])
    return 1  # not reached
