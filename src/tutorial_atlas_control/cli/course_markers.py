"""Command line of course_markers.py: the course's shapes for rviz (vrc_task_2.launch).

It keeps roslaunch's command line (MODEL_FILE and `name:=value` ROS arguments, usage from
course/markers_node.py's docstring), as state_publisher.py does.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

import mujoco

from tutorial_atlas_control.cli.convention import EXIT_INTERRUPTED, EXIT_REFUSED
from tutorial_atlas_control.course import CourseError, course_shapes

PROG = 'course_markers.py'
HELP_OPTIONS = ('-h', '--help')


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of scripts/course_markers.py (`argv` with the program name first)."""
    from tutorial_atlas_control.course import markers_node  # noqa: PLC0415 - rospy's import
    argv = list(sys.argv if argv is None else argv)
    plain = [arg for arg in argv[1:] if ':=' not in arg]
    if len(plain) != 1 or plain[0] in HELP_OPTIONS:
        asked = bool(plain) and plain[0] in HELP_OPTIONS
        print(markers_node.__doc__.strip(), file=sys.stdout if asked else sys.stderr)
        return 0 if asked else EXIT_REFUSED
    try:
        model = mujoco.MjModel.from_xml_path(str(Path(plain[0])))
        shapes = course_shapes(model)
    except (ValueError, CourseError) as err:
        print(f'{PROG}: error: {plain[0]}: {" ".join(str(err).split())}', file=sys.stderr)
        return EXIT_REFUSED
    try:
        markers_node.publish_and_wait(shapes)
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    return 0
