"""The stereo pair rendered offscreen by MuJoCo from a state of the simulated world.

The cameras are added to a copy of the simulated model (MjSpec: two cameras on `head`, no
body or joint, so the physics is untouched), and a state is the world's qpos: the robot and
anything loose, such as the VRC course's cinder blocks. Software OpenGL (llvmpipe) pays for
every pixel, so the camera scene drops what costs most and shows least at 800 x 800:
multisampling, shadows and reflections (measured in docs/cameras.md).

mujoco is imported inside the functions: MUJOCO_GL must be set before its first import.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

import numpy as np

from tutorial_atlas_control.stereo.multisense import (
    FAR_M,
    HEAD_BODY,
    HEIGHT_PX,
    HFOV_RAD,
    NEAR_M,
    NOISE_STDDEV,
    SIDES,
    WIDTH_PX,
)

__all__ = ['CAMERA_PREFIX', 'ImageNoise', 'StereoRenderer', 'camera_model']

#: The added cameras' names in the model: multisense_left, multisense_right.
CAMERA_PREFIX = 'multisense_'
#: MuJoCo's camera looks along its -z with y up; DRCSim's camera frame looks along x with z
#: up: the camera's x (image right) is the head's -y, its y (image up) the head's z.
_XYAXES = (0.0, -1.0, 0.0, 0.0, 0.0, 1.0)


def camera_model(model_file: str) -> Any:
    """The model in `model_file` with the pair on its head, set for offscreen rendering."""
    import mujoco  # noqa: PLC0415 - after MUJOCO_GL is set

    spec = mujoco.MjSpec.from_file(str(model_file))
    head = spec.body(HEAD_BODY)
    if head is None:
        raise ValueError(f'{model_file} has no body {HEAD_BODY!r} to carry the cameras')
    for side in SIDES:
        camera = head.add_camera()
        camera.name = CAMERA_PREFIX + side.name
        camera.pos = list(side.offset_m)
        camera.alt.type = mujoco.mjtOrientation.mjORIENTATION_XYAXES
        camera.alt.xyaxes = list(_XYAXES)
        camera.fovy = float(np.degrees(HFOV_RAD))  # square images: vertical fov = hfov
    model = spec.compile()
    model.vis.map.znear = NEAR_M / model.stat.extent
    model.vis.map.zfar = FAR_M / model.stat.extent
    model.vis.quality.offsamples = 0
    model.vis.global_.offwidth = max(model.vis.global_.offwidth, WIDTH_PX)
    model.vis.global_.offheight = max(model.vis.global_.offheight, HEIGHT_PX)
    return model


class ImageNoise:
    """DRCSim's camera noise: one Gaussian value per pixel added to its three channels.

    Drawing 640 000 normals a frame costs more than the render; the values come from a
    table drawn once, read from a random offset each frame (a pixel's noise is still
    Gaussian and independent of its neighbours'; frames share a table of 2^22 values).
    """

    def __init__(self, stddev: float = NOISE_STDDEV, seed: int | None = None,
                 table_size: int = 1 << 22) -> None:
        self.rng = np.random.default_rng(seed)
        levels = self.rng.normal(0.0, stddev * 255.0, table_size)
        self.table = np.rint(levels).astype(np.int16)
        self._work = np.empty((0,), np.int16)

    def apply(self, image: np.ndarray) -> np.ndarray:
        """`image` (h, w, 3 uint8) with noise, saturated to [0, 255]: a new array."""
        h, w, _ = image.shape
        count = h * w
        start = int(self.rng.integers(0, self.table.size - count + 1))
        work = image.astype(np.int16)
        work += self.table[start:start + count].reshape(h, w, 1)
        np.clip(work, 0, 255, out=work)
        return work.astype(np.uint8)


class StereoRenderer:
    """Renders the pair's images of a world state (one OpenGL context, reused)."""

    def __init__(self, model: Any, noise: ImageNoise | None = None) -> None:
        import mujoco  # noqa: PLC0415 - after MUJOCO_GL is set

        self._mujoco = mujoco
        self.model = model
        self.data = mujoco.MjData(model)
        self.noise = noise
        self.renderer = mujoco.Renderer(model, height=HEIGHT_PX, width=WIDTH_PX)
        flags = mujoco.mjtRndFlag
        self._off = (flags.mjRND_SHADOW, flags.mjRND_REFLECTION)

    def set_state(self, qpos: np.ndarray) -> None:
        """Places the world at `qpos` (the simulator's whole qpos)."""
        mujoco, model, data = self._mujoco, self.model, self.data
        if qpos.shape != (model.nq,):
            raise ValueError(f'a state of {qpos.shape[0]} positions for a model of {model.nq}')
        data.qpos[:] = qpos
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)
        mujoco.mj_camlight(model, data)

    def render(self, side: str) -> np.ndarray:
        """The image (800 x 800 x 3 uint8, top row first) of camera `side` at the state."""
        renderer = self.renderer
        renderer.update_scene(self.data, CAMERA_PREFIX + side)
        for flag in self._off:
            renderer.scene.flags[flag] = False
        image = renderer.render()
        return self.noise.apply(image) if self.noise is not None else image

    def render_sides(self, qpos: np.ndarray, sides: Iterable[str]) -> dict[str, np.ndarray]:
        """The images of `sides` at `qpos`."""
        self.set_state(qpos)
        return {side: self.render(side) for side in sides}

    def close(self) -> None:
        self.renderer.close()

    def __enter__(self) -> StereoRenderer:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()
