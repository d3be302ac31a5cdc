"""The multisense_sl head's stereo pair as DRCSim described it, and its camera_info.

One place for the pair's numbers (multisense_sl.urdf's multicamera block and its camera
frames on `head`) and for the pinhole model they imply, so that the renderer, the node and
stereo_image_proc's inputs agree (the frames' origins are sensors/frames.py's). Pure
numbers, no MuJoCo, no ROS.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from tutorial_atlas_control.sensors import CAMERA_FRAMES, HEAD_LINK

__all__ = ['BASELINE_M', 'DEFAULT_FPS', 'FAR_M', 'HEAD_BODY', 'HFOV_RAD', 'HEIGHT_PX',
           'NEAR_M', 'NOISE_STDDEV', 'OPTICAL_FRAME', 'SIDES', 'WIDTH_PX', 'CameraSide',
           'Intrinsics', 'intrinsics']

WIDTH_PX = 800
HEIGHT_PX = 800
#: Horizontal field of view (80 degrees); square pixels, so the vertical one too.
HFOV_RAD = 1.3962634
#: gazebo_ros_multicamera's hackBaseline: the right camera's P[3] = -fx * baseline.
BASELINE_M = 0.07
NEAR_M = 0.02
FAR_M = 300.0
#: Gaussian noise added per pixel to all three channels, in units of the [0, 1] range.
NOISE_STDDEV = 0.007
#: The sensor's update_rate, and set_fps's upper limit at 800 x 800 (imager mode 1).
DEFAULT_FPS = 30.0
#: The body the cameras ride on (the MuJoCo model's and the URDF's `head`).
HEAD_BODY = HEAD_LINK
#: Both images' header.frame_id: the plugin's frameName, the right one's too (DRCSim left
#: rightFrameName out; the baseline is in the right camera_info's P instead).
OPTICAL_FRAME = 'left_camera_optical_frame'


@dataclass(frozen=True)
class CameraSide:
    """One camera of the pair: its topics' namespace and its place on `head`."""

    name: str  # 'left' or 'right'
    offset_m: tuple[float, float, float]  # camera frame's origin in the head frame

    @property
    def namespace(self) -> str:
        return f'/multisense_sl/camera/{self.name}'

    @property
    def frame(self) -> str:
        """The URDF's camera frame (x forward); the optical frame is it turned by
        rpy (-pi/2, 0, -pi/2): z forward, x right, y down."""
        return f'{self.name}_camera_frame'


#: The camera frames' origins on `head`: sensors/frames.py's, the URDF's numbers.
_ON_HEAD = {frame.child: frame.xyz_m for frame in CAMERA_FRAMES if frame.parent == HEAD_LINK}
SIDES = tuple(CameraSide(name, _ON_HEAD[f'{name}_camera_frame']) for name in ('left', 'right'))


@dataclass(frozen=True)
class Intrinsics:
    """A camera_info's numbers: K (3 x 3) and P (3 x 4), row-major, D all zero."""

    width: int
    height: int
    k: tuple[float, ...]
    p: tuple[float, ...]

    @property
    def fx(self) -> float:
        return self.k[0]


def intrinsics(side: str, width: int = WIDTH_PX, height: int = HEIGHT_PX,
               hfov_rad: float = HFOV_RAD, baseline_m: float = BASELINE_M) -> Intrinsics:
    """The pinhole model of the rendered image: fx = fy = w/2 / tan(hfov/2).

    The principal point is the image's centre in ROS's convention (pixel centres at
    integers): ((w - 1)/2, (h - 1)/2), where an OpenGL render puts the optical axis. Gazebo's
    camera utils wrote (w + 1)/2, one pixel off; the render here is what stereo must match.
    The right camera's P has Tx = -fx * baseline, as gazebo_ros_multicamera's hackBaseline.
    """
    if side not in ('left', 'right'):
        raise ValueError(f"side must be 'left' or 'right', got {side!r}")
    fx = width / 2.0 / math.tan(hfov_rad / 2.0)
    cx, cy = (width - 1) / 2.0, (height - 1) / 2.0
    tx = -fx * baseline_m if side == 'right' else 0.0
    return Intrinsics(width, height, (fx, 0.0, cx, 0.0, fx, cy, 0.0, 0.0, 1.0),
                      (fx, 0.0, cx, tx, 0.0, fx, cy, 0.0, 0.0, 0.0, 1.0, 0.0))
