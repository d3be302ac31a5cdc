"""Render a recorded run offscreen to an MP4 or GIF, from its bag alone.

Each video frame puts the model in the recorded state at the frame's time: the pelvis pose
from `/ground_truth_odom` (100 Hz, interpolated) and the joint angles from
`/atlas/joint_states` (1 kHz, latest sample at or before the frame), and draws it with
`mujoco.Renderer` through the model's `track` camera.

MuJoCo picks its OpenGL backend when it is first imported, so this module imports mujoco
only inside :func:`prepare_gl` and the functions that render: with no display and no
MUJOCO_GL set, it selects software OSMesa first. Shadows, reflections and multisampling
are switched off: in software rendering they cost most of the frame time.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from tutorial_atlas_control import topics
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import NUM_JOINTS, joint_index
from tutorial_atlas_control.sim import CAMERA
from tutorial_atlas_control.units import finite_number

if TYPE_CHECKING:  # pragma: no cover - typing only; mujoco is imported lazily
    from tutorial_atlas_control.bags.reader import BagData
    from tutorial_atlas_control.sim import AtlasModel

__all__ = [
    'CAMERA',
    'DEFAULT_FPS',
    'DEFAULT_SIZE',
    'VIDEO_SUFFIXES',
    'RenderError',
    'RunStates',
    'StateRenderer',
    'VideoResult',
    'check_output_path',
    'parse_size',
    'prepare_gl',
    'render_bag_video',
    'render_states',
    'states_from_bag',
]

DEFAULT_FPS = 30.0
DEFAULT_SIZE = (640, 480)
#: Output formats by file suffix.
VIDEO_SUFFIXES = ('.mp4', '.gif')
#: Bounds of a sane request (pixels, frames per second).
MIN_SIDE_PX, MAX_SIDE_PX = 16, 4096
MIN_FPS, MAX_FPS = 1.0, 240.0
#: imageio-ffmpeg quality for H.264 (0-10, 10 = best); 7 keeps a 5 s clip well under 1 MB.
MP4_QUALITY = 7
#: x264 speed preset: 'veryfast' needs about a third of the default's CPU, same quality setting.
X264_PRESET = 'veryfast'
#: Colours per GIF frame (each frame gets its own palette).
GIF_COLORS = 256
#: Where the time stamp is drawn (pixels from the top-left corner).
LABEL_MARGIN_PX = 8


class RenderError(AtlasControlError):
    """The video cannot be rendered or written; the message says what to change."""


# ---------------------------------------------------------------------------- set-up


def prepare_gl() -> None:
    """Choose software OSMesa when there is no display, before mujoco is imported.

    Raises:
        RenderError: mujoco was already imported without a usable backend choice.
    """
    if os.environ.get('MUJOCO_GL') or os.environ.get('DISPLAY'):
        return
    if 'mujoco' in sys.modules:
        raise RenderError('mujoco was imported before MUJOCO_GL was set and there is no '
                          'display; start Python with MUJOCO_GL=osmesa (`source env.sh` does).')
    os.environ['MUJOCO_GL'] = 'osmesa'
    os.environ.setdefault('PYOPENGL_PLATFORM', 'osmesa')


def parse_size(text: str) -> tuple[int, int]:
    """'640x480' -> (640, 480).

    Raises:
        RenderError: not WxH, or a side outside MIN_SIDE_PX..MAX_SIDE_PX.
    """
    parts = text.lower().split('x')
    try:
        width, height = (int(part) for part in parts)
    except ValueError:
        raise RenderError(f'{text!r} is not WIDTHxHEIGHT in pixels, e.g. 640x480.') from None
    for side in (width, height):
        if not MIN_SIDE_PX <= side <= MAX_SIDE_PX:
            raise RenderError(f'{text!r}: each side must be {MIN_SIDE_PX}..{MAX_SIDE_PX} pixels.')
    return width, height


def parse_fps(text: str) -> float:
    """A video frame rate (frames per s of sim time) within MIN_FPS..MAX_FPS.

    Raises:
        RenderError: not a number, or out of range.
    """
    fps = finite_number(text, allow_text=True)
    if fps is None or not MIN_FPS <= fps <= MAX_FPS:
        raise RenderError(f'{text!r} is out of range; choose {MIN_FPS:g}..{MAX_FPS:g} frames/s.')
    return fps


def check_output_path(path: Path | str, width: int, height: int, fps: float) -> Path:
    """Validate the output before spending time on rendering.

    Raises:
        RenderError: unknown suffix, odd size for MP4, bad fps, or the file cannot be written.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in VIDEO_SUFFIXES:
        raise RenderError(f'{path}: unknown video format {suffix or "(no suffix)"!r}; '
                          f'name the file .mp4 (H.264) or .gif.')
    if suffix == '.mp4' and (width % 2 or height % 2):
        raise RenderError(f'MP4 (H.264, yuv420p) needs an even width and height, got '
                          f'{width}x{height}.')
    if not (np.isfinite(fps) and MIN_FPS <= fps <= MAX_FPS):
        raise RenderError(f'--fps {fps:g} is out of range; choose {MIN_FPS:g}..{MAX_FPS:g}.')
    if path.is_dir():
        raise RenderError(f'{path} is a directory; give a file name ending in .mp4 or .gif.')
    parent = path.parent if str(path.parent) else Path('.')
    if not parent.is_dir():
        raise RenderError(f'cannot write {path}: directory {parent} does not exist.')
    if not os.access(parent, os.W_OK) or (path.exists() and not os.access(path, os.W_OK)):
        raise RenderError(f'cannot write {path}: permission denied.')
    return path


# ---------------------------------------------------------------------------- states


@dataclass(frozen=True)
class RunStates:
    """The robot's pose at each frame time (s): pelvis position (m), quaternion w x y z,
    joint angles (rad) in JOINT_NAMES order (NaN = not recorded, drawn at 0)."""

    t_s: np.ndarray
    pelvis_position_m: np.ndarray     # (frames, 3)
    pelvis_quat_wxyz: np.ndarray      # (frames, 4)
    joint_position_rad: np.ndarray    # (frames, NUM_JOINTS)

    def __len__(self) -> int:
        return len(self.t_s)


def _interpolate_pose(t_s: np.ndarray, pose_t_s: np.ndarray, position_m: np.ndarray,
                      quat_xyzw: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position by linear interpolation, orientation by normalized lerp (shortest arc)."""
    position = np.column_stack([np.interp(t_s, pose_t_s, position_m[:, axis])
                                for axis in range(3)])
    quat = quat_xyzw[:, [3, 0, 1, 2]].copy()
    # Flip signs so neighbouring samples lie in the same hemisphere before blending.
    for row in range(1, len(quat)):
        if np.dot(quat[row], quat[row - 1]) < 0.0:
            quat[row] = -quat[row]
    after = np.clip(np.searchsorted(pose_t_s, t_s, side='right'), 1, max(len(pose_t_s) - 1, 1))
    before = after - 1
    if len(pose_t_s) < 2:
        blended = np.repeat(quat[:1], len(t_s), axis=0)
    else:
        span = pose_t_s[after] - pose_t_s[before]
        weight = np.clip((t_s - pose_t_s[before]) / np.where(span > 0, span, 1.0), 0.0, 1.0)
        blended = quat[before] * (1.0 - weight)[:, None] + quat[after] * weight[:, None]
    blended /= np.linalg.norm(blended, axis=1, keepdims=True)
    return position, blended


def states_from_bag(data: BagData, fps: float = DEFAULT_FPS) -> RunStates:
    """Sample the recorded run at `fps` over the time both pose sources cover.

    Raises:
        RenderError: the bag lacks /ground_truth_odom or /atlas/joint_states.
    """
    pelvis, states = data.pelvis, data.joint_states
    missing = [topic for topic, series in ((topics.GROUND_TRUTH_ODOM, pelvis),
                                           (topics.JOINT_STATES, states))
               if series is None or not len(series.t_s)]
    if missing:
        raise RenderError(f'{data.path} has no {" and no ".join(missing)}; the video needs the '
                          'pelvis pose and the joint angles.')
    assert pelvis is not None and states is not None
    start_s = max(float(pelvis.t_s[0]), float(states.t_s[0]))
    end_s = min(float(pelvis.t_s[-1]), float(states.t_s[-1]))
    if end_s < start_s:
        raise RenderError(f'{data.path}: {topics.GROUND_TRUTH_ODOM} and {topics.JOINT_STATES} '
                          'do not overlap in time; nothing to render.')
    count = int(np.floor((end_s - start_s) * fps + 1e-9)) + 1
    t_s = start_s + np.arange(count) / fps
    position, quat = _interpolate_pose(t_s, pelvis.t_s, pelvis.position_m, pelvis.orientation_xyzw)
    rows = np.clip(np.searchsorted(states.t_s, t_s, side='right') - 1, 0, len(states.t_s) - 1)
    joints = np.full((count, NUM_JOINTS), np.nan)
    for column, name in enumerate(states.names):
        index = joint_index(name)
        if index is not None:
            joints[:, index] = states.position[rows, column]
    return RunStates(t_s, position, quat, joints)


# ---------------------------------------------------------------------------- rendering


class StateRenderer:
    """Draws the Atlas model in given poses through the `track` camera; closes its GL context.

    Use as a context manager, or call close().
    """

    def __init__(self, width: int, height: int, atlas: AtlasModel | None = None,
                 camera: str = CAMERA) -> None:
        prepare_gl()
        # After prepare_gl(): MuJoCo picks its OpenGL back-end when first imported.
        import mujoco  # noqa: PLC0415

        from tutorial_atlas_control.sim import load_model  # noqa: PLC0415 - imports mujoco

        self._mujoco = mujoco
        self.atlas = atlas if atlas is not None else load_model()
        model = self.atlas.model
        # Our own offscreen buffer limits: a request larger than the file's is fine.
        model.vis.global_.offwidth = max(int(model.vis.global_.offwidth), width)
        model.vis.global_.offheight = max(int(model.vis.global_.offheight), height)
        model.vis.quality.offsamples = 0  # no multisampling: much faster in OSMesa
        if mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, camera) < 0:
            raise RenderError(f'the model has no camera named {camera!r}.')
        self.camera = camera
        self.data = mujoco.MjData(model)
        try:
            self._renderer = mujoco.Renderer(model, height=height, width=width)
        except Exception as err:
            raise RenderError(f'cannot open an offscreen OpenGL context ({err}); on a machine '
                              'without a display install libosmesa6 and set MUJOCO_GL=osmesa.'
                              ) from err

    def __enter__(self) -> StateRenderer:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Free the GL context (idempotent)."""
        renderer, self._renderer = getattr(self, '_renderer', None), None
        if renderer is not None:
            renderer.close()

    def render(self, pelvis_position_m: np.ndarray, pelvis_quat_wxyz: np.ndarray,
               joint_position_rad: np.ndarray) -> np.ndarray:
        """One (height, width, 3) uint8 image of the robot in this pose."""
        if self._renderer is None:
            raise RenderError('the renderer is closed.')
        mujoco = self._mujoco
        atlas, data = self.atlas, self.data
        adr = atlas.free_qpos_adr
        data.qpos[adr:adr + 3] = pelvis_position_m
        data.qpos[adr + 3:adr + 7] = pelvis_quat_wxyz
        data.qpos[atlas.qpos_adr] = np.nan_to_num(joint_position_rad, nan=0.0)
        # Kinematics and the subtree centre of mass the trackcom camera follows.
        mujoco.mj_kinematics(atlas.model, data)
        mujoco.mj_comPos(atlas.model, data)
        mujoco.mj_camlight(atlas.model, data)
        renderer = self._renderer
        renderer.update_scene(data, camera=self.camera)
        flags = renderer.scene.flags
        flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
        flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False
        return renderer.render()


def _frames(states: RunStates, width: int, height: int, progress: bool,
            time_label: bool) -> Iterator[np.ndarray]:
    from tqdm import tqdm  # noqa: PLC0415 - only videos need it

    with StateRenderer(width, height) as renderer, \
            tqdm(total=len(states), unit='frame', desc='rendering', file=sys.stderr,  # a tty's
                 disable=None if progress else True, leave=False, mininterval=0.5) as bar:
        for row in range(len(states)):
            frame = renderer.render(states.pelvis_position_m[row], states.pelvis_quat_wxyz[row],
                                    states.joint_position_rad[row])
            if time_label:
                frame = _label(frame, f't = {states.t_s[row]:6.2f} s')
            bar.update()
            yield frame


def _label(frame: np.ndarray, text: str) -> np.ndarray:
    """Draw `text` in the top-left corner, white on a dark box."""
    from PIL import Image, ImageDraw  # noqa: PLC0415 - only videos need it

    image = Image.fromarray(frame)
    draw = ImageDraw.Draw(image)
    left, top, right, bottom = draw.textbbox((LABEL_MARGIN_PX, LABEL_MARGIN_PX), text)
    draw.rectangle((left - 3, top - 3, right + 3, bottom + 3), fill=(0, 0, 0))
    draw.text((LABEL_MARGIN_PX, LABEL_MARGIN_PX), text, fill=(255, 255, 255))
    return np.asarray(image)


def _write_mp4(path: Path, frames: Iterable[np.ndarray], fps: float) -> int:
    import imageio.v2 as imageio  # noqa: PLC0415 - only videos need it (slow to import)

    count = 0
    writer = imageio.get_writer(str(path), format='FFMPEG', mode='I', fps=fps, codec='libx264',
                                quality=MP4_QUALITY, pixelformat='yuv420p', macro_block_size=1,
                                ffmpeg_log_level='error', output_params=['-preset', X264_PRESET])
    try:
        for frame in frames:
            writer.append_data(frame)
            count += 1
    finally:
        writer.close()
    return count


def _write_gif(path: Path, frames: Iterable[np.ndarray], fps: float) -> int:
    from PIL import Image  # noqa: PLC0415 - only videos need it

    images = [Image.fromarray(frame).quantize(GIF_COLORS, method=Image.Quantize.FASTOCTREE)
              for frame in frames]
    if images:
        # GIF delays are whole centiseconds; Pillow rounds the millisecond value.
        images[0].save(path, save_all=True, append_images=images[1:], loop=0,
                       duration=1000.0 / fps, optimize=False)
    return len(images)


@dataclass(frozen=True)
class VideoResult:
    """What was written: file, frames, frames per second, covered sim time span (s)."""

    path: Path
    frames: int
    fps: float
    start_s: float
    end_s: float


def render_states(states: RunStates, path: Path | str, fps: float = DEFAULT_FPS,
                  size: tuple[int, int] = DEFAULT_SIZE, progress: bool = True,
                  time_label: bool = True) -> VideoResult:
    """Render `states` (one frame each) to `path` (.mp4 or .gif).

    Raises:
        RenderError: bad output path/format/size, no frames, or the writer failed.
    """
    width, height = size
    path = check_output_path(path, width, height, fps)
    if not len(states):
        raise RenderError('no frames to render.')
    write = _write_mp4 if path.suffix.lower() == '.mp4' else _write_gif
    try:
        count = write(path, _frames(states, width, height, progress, time_label), fps)
    except OSError as err:
        raise RenderError(f'cannot write {path}: {err.strerror or err}.') from err
    except RuntimeError as err:  # imageio-ffmpeg reports encoder failures this way
        raise RenderError(f'the video encoder failed on {path}: {err}') from err
    return VideoResult(path, count, fps, float(states.t_s[0]), float(states.t_s[-1]))


def render_bag_video(data: BagData, path: Path | str, fps: float = DEFAULT_FPS,
                     size: tuple[int, int] = DEFAULT_SIZE, progress: bool = True) -> VideoResult:
    """Render the run in `data` (from reader.read_bag) to `path`.

    Frame times are seconds from the bag's start (as in the analysis), labelled on the frame.

    Raises:
        RenderError: see :func:`render_states` and :func:`states_from_bag`.
    """
    check_output_path(path, *size, fps)
    return render_states(states_from_bag(data, fps), path, fps, size, progress)

