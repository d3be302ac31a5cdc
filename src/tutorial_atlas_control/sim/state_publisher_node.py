"""Start Debian's robot_state_publisher on the simulated model's URDF (atlas.launch with
tf_publisher:=robot_state_publisher; by default the simulator publishes the links itself).

usage: state_publisher.py MODEL_FILE [ROS arguments]

Sets /robot_description to the URDF beside MODEL_FILE (urdf.matching_urdf) and then
becomes robot_state_publisher (exec, same ROS name, parameters and remappings), as DRCSim's
launch ran it. A model without a matching URDF gets no robot_state_publisher: this exits 0
quietly, and the simulator, which makes the same check, logs the one warning.
"""

from __future__ import annotations

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.topics import ROBOT_DESCRIPTION_PARAM

#: The Debian package and executable started.
RSP_PACKAGE = 'robot_state_publisher'
RSP_EXECUTABLE = 'robot_state_publisher'


class StatePublisherError(AtlasControlError):
    """robot_state_publisher cannot be started; the message says what to install or fix."""


def robot_state_publisher_executable() -> str:
    """Path of robot_state_publisher (Debian: /usr/lib/robot_state_publisher/...).

    Raises:
        StatePublisherError: it is not installed.
    """
    import roslib.packages  # noqa: PLC0415 - the module imports where ROS is not installed
    try:
        found = roslib.packages.find_node(RSP_PACKAGE, RSP_EXECUTABLE)
    except Exception:  # noqa: BLE001 - rospkg raises several kinds for a missing package
        found = []
    if not found:
        raise StatePublisherError('robot_state_publisher is not installed; run `make setup` '
                                  '(Debian package ros-robot-state-publisher).')
    return found[0]


def set_robot_description(description: str) -> None:
    """Put the URDF where robot_state_publisher reads it: the master's /robot_description.

    Raises:
        OSError: the master cannot be reached.
    """
    import rosgraph  # noqa: PLC0415 - the module imports where ROS is not installed
    rosgraph.Master('/state_publisher').setParam(ROBOT_DESCRIPTION_PARAM, description)
