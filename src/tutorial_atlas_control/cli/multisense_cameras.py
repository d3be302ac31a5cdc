"""Command line of multisense_cameras.py: the head's stereo pair (atlas.launch).

It keeps roslaunch's command line: MODEL_FILE and `name:=value` ROS arguments; usage from
stereo/camera_node.py's docstring. MuJoCo renders offscreen with $MUJOCO_GL (osmesa when
unset: a display's GLFW window is not wanted here).
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from tutorial_atlas_control.cli.convention import EXIT_INTERRUPTED, EXIT_REFUSED

PROG = 'multisense_cameras.py'
HELP_OPTIONS = ('-h', '--help')
NODE_NAME = 'multisense_cameras'


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of scripts/multisense_cameras.py (`argv` with the program name first)."""
    if not os.environ.get('MUJOCO_GL'):
        os.environ['MUJOCO_GL'] = os.environ['PYOPENGL_PLATFORM'] = 'osmesa'
    import rospy  # noqa: PLC0415 - after MUJOCO_GL, as every import below

    from tutorial_atlas_control.stereo import (  # noqa: PLC0415
        ImageNoise,
        StereoRenderer,
        camera_model,
        camera_node,
    )
    argv = list(sys.argv if argv is None else argv)
    plain = [arg for arg in argv[1:] if ':=' not in arg]
    if len(plain) != 1 or plain[0] in HELP_OPTIONS:
        asked = bool(plain) and plain[0] in HELP_OPTIONS
        print((camera_node.__doc__ or '').strip(), file=sys.stdout if asked else sys.stderr)
        return 0 if asked else EXIT_REFUSED
    rospy.init_node(NODE_NAME, argv=argv)
    _drop_clock(rospy)
    noise = rospy.get_param('~noise', True)
    try:
        model = camera_model(str(Path(plain[0])))
        renderer = StereoRenderer(model, ImageNoise() if noise else None)
    except Exception as err:  # noqa: BLE001 - MuJoCo's and OpenGL's errors, said in one line
        print(f'{PROG}: error: cannot render {plain[0]}: {" ".join(str(err).split())}',
              file=sys.stderr)
        return EXIT_REFUSED
    node = camera_node.CameraNode(renderer)
    try:
        node.spin()
    except KeyboardInterrupt:
        return EXIT_INTERRUPTED
    finally:
        print(node.summary(), flush=True)
        renderer.close()
    return 0


def _drop_clock(rospy: Any) -> None:
    """Unsubscribes rospy's own /clock subscriber (made under /use_sim_time): the node's
    stamps are the rendered states' sim times, and decoding 1000 clocks a second cost it
    0.07 s of CPU per second of sim time while nobody looked (rospy offers no public way)."""
    subscriber = getattr(rospy.impl.simtime, '_clock_sub', None)
    if subscriber is not None:
        subscriber.unregister()
