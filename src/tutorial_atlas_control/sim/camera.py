"""How the robot is looked at: the model's tracking camera, for the videos and the viewer.

The videos (bags/render.py) draw through the model's `track` camera; the interactive
viewer (node/) gets a free camera that looks at the pelvis from the same direction and
distance, so the window shows what the videos show and the mouse can still turn it.

mujoco is imported inside the functions: bags/render.py imports this module before it
chooses MuJoCo's OpenGL back-end, which MuJoCo fixes when it is first imported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tutorial_atlas_control.errors import AtlasControlError

__all__ = ['CAMERA', 'CameraError', 'ViewerView', 'configure_viewer_camera',
           'configure_viewer_scene', 'viewer_view']

#: The model's camera that follows the pelvis (sim/atlas_v1.xml).
CAMERA = 'track'


class CameraError(AtlasControlError):
    """The model lacks the camera asked for; the message names it."""


@dataclass(frozen=True)
class ViewerView:
    """A MuJoCo free-camera view: distance (m), azimuth and elevation (degrees)."""

    distance_m: float
    azimuth_deg: float
    elevation_deg: float


def _camera_id(model: object, camera: str) -> int:
    import mujoco  # noqa: PLC0415 - after render.prepare_gl (module docstring)

    camera_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera)
    if camera_id < 0:
        raise CameraError(f'the model has no camera named {camera!r}.')
    return camera_id


def viewer_view(model: object, camera: str = CAMERA) -> ViewerView:
    """The video camera's view as the interactive viewer's tracking camera sees it.

    The model's `track` camera sits at a fixed offset from the pelvis and looks at it; the
    viewer's camera looks at the pelvis from the same direction and distance.

    Raises:
        CameraError: the model has no such camera.
    """
    import mujoco  # noqa: PLC0415 - after render.prepare_gl (module docstring)

    camera_id = _camera_id(model, camera)
    offset_m = np.asarray(model.cam_pos[camera_id], dtype=float)
    rotation = np.zeros(9)
    mujoco.mju_quat2Mat(rotation, model.cam_quat[camera_id])
    forward = -rotation.reshape(3, 3)[:, 2]  # cameras look along their -z axis
    return ViewerView(float(np.linalg.norm(offset_m)),
                      float(np.degrees(np.arctan2(forward[1], forward[0]))),
                      float(np.degrees(np.arcsin(np.clip(forward[2], -1.0, 1.0)))))


def configure_viewer_camera(cam: object, model: object, data: object,
                            camera: str = CAMERA) -> None:
    """Point a viewer's MjvCamera at the robot: tracking the pelvis, from `camera`'s view.

    `data` must hold the current kinematics (the tracked point is the pelvis subtree's
    centre of mass).

    Raises:
        CameraError: the model has no such camera.
    """
    import mujoco  # noqa: PLC0415 - after render.prepare_gl (module docstring)

    view = viewer_view(model, camera)
    body = int(model.cam_bodyid[_camera_id(model, camera)])
    cam.type = mujoco.mjtCamera.mjCAMERA_TRACKING
    cam.trackbodyid = body
    cam.fixedcamid = -1
    cam.distance = view.distance_m
    cam.azimuth = view.azimuth_deg
    cam.elevation = view.elevation_deg
    cam.lookat[:] = data.subtree_com[body]


def configure_viewer_scene(scene: object) -> None:
    """The video's look in the viewer: no shadows, no reflections.

    With software OpenGL (no GPU, Xvfb) they cost most of each frame, and the viewer's
    render thread competes with the simulation for the CPU. The Rendering panel turns them
    back on.
    """
    import mujoco  # noqa: PLC0415 - after render.prepare_gl (module docstring)

    scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
    scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False
