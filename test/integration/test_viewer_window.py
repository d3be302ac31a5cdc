"""The MuJoCo viewer window (atlas.launch gui:=true) shows the whole robot, under a real X
server (Xvfb, software OpenGL), as a user opening it sees it.

How the robot's pixels are found: from the model's own material colours. The head is the
only orange thing in the scene, the legs and upper arms are blue; light changes their
brightness, not their proportions r : g : b (support.xdisplay.material_mask). The grey
and dark parts cannot be told from the grey floor, so the feet are judged from the blue
shins above them: the shins' lowest pixel must leave room for the feet (their height on
screen, from the model's ankle height and the robot's height on screen) above the window's
edge. MuJoCo's panels are hidden when the window opens (Tab shows them): no section title
bar of its left panel is drawn.
"""

from __future__ import annotations

import subprocess
import time
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from support.launch import wait_sim_time
from support.xdisplay import (
    display_env,
    find_reset_button,
    find_window,
    material_mask,
    screenshot,
    xvfb,
)
from tutorial_atlas_control.processes import (
    free_local_port,
    ros_environment,
    stop_tree,
)
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.camera import configure_viewer_camera

#: A pixel is the material's colour when its r : g : b is this close (chromaticity distance).
#: The blue (0.2, 0.3, 0.55) and the sky near the horizon (about 0.33, 0.43, 0.58) are 0.11
#: apart; lit, shaded and anti-aliased blue pixels lie within 0.03 of the material.
CHROMA_TOLERANCE = 0.05
#: Darker pixels (mean of r, g, b in 0..1) have too little colour to judge.
MIN_BRIGHTNESS = 0.08
#: Fewer pixels than this of a colour is noise, not the head (or the legs). The head of the
#: robot spanning a third of an 800 x 533 window covers about 600 pixels.
MIN_HEAD_PIXELS = 150
MIN_LEG_PIXELS = 1000
#: The robot, head top to feet, spans at least this much of the window's height.
MIN_SPAN_FRACTION = 1.0 / 3.0
#: Sim time (s) at which the screenshot is taken: standing, after the 1 s pin.
SCREENSHOT_AT_S = 3.0
REPO = Path(__file__).resolve().parents[2]


@dataclass(frozen=True)
class RobotOnScreen:
    """What the colours say about the robot in one image (rows from the top, pixels)."""

    height_px: int
    head_pixels: int
    leg_pixels: int
    top_row: int        # the head's highest pixel
    shins_row: int      # the blue legs' lowest pixel
    feet_px: float      # the feet's height on screen (below the shins)

    @property
    def span_fraction(self) -> float:
        return (self.shins_row + self.feet_px - self.top_row) / self.height_px

    @property
    def feet_on_screen(self) -> bool:
        return self.shins_row + self.feet_px < self.height_px

    def shows_whole_robot(self) -> bool:
        return (self.head_pixels >= MIN_HEAD_PIXELS and self.leg_pixels >= MIN_LEG_PIXELS
                and self.feet_on_screen and self.span_fraction >= MIN_SPAN_FRACTION)


def robot_on_screen(image: np.ndarray, m: mujoco.MjModel) -> RobotOnScreen:
    orange = material_mask(image, m.material('orange').rgba, CHROMA_TOLERANCE, MIN_BRIGHTNESS)
    blue = material_mask(image, m.material('blue').rgba, CHROMA_TOLERANCE, MIN_BRIGHTNESS)
    height = image.shape[0]
    head_rows, leg_rows = np.nonzero(orange.any(axis=1))[0], np.nonzero(blue.any(axis=1))[0]
    top = int(head_rows[0]) if len(head_rows) else height
    shins = int(leg_rows[-1]) if len(leg_rows) else 0
    feet_share = _ankle_share()
    feet_px = max(0.0, (shins - top)) * feet_share / (1.0 - feet_share)
    return RobotOnScreen(height, int(orange.sum()), int(blue.sum()), top, shins, feet_px)


def _ankle_share() -> float:
    """Ankle height / head height, standing, from the model: the feet's share of the robot's
    height on screen (the part below the shins)."""
    atlas = atlas_model.load_model()
    data = mujoco.MjData(atlas.model)
    atlas_model.reset_to_initial(atlas, data)
    return float(data.body('l_talus').xpos[2] / data.body('head').xpos[2])


def test_viewer_window_shows_the_whole_robot(tmp_path: Path) -> None:
    m = atlas_model.load_model().model
    with xvfb(tmp_path / 'xvfb.log') as display:
        port = free_local_port()
        env = ros_environment(port, tmp_path / 'ros_log', base=display_env(display))
        log = open(tmp_path / 'launch.log', 'w')  # noqa: SIM115 - closed below
        process = subprocess.Popen(
            ['roslaunch', '-p', str(port), 'tutorial_atlas_control', 'atlas.launch', 'gui:=true',
             'record:=false'], env=env, stdout=log, stderr=subprocess.STDOUT,
            start_new_session=True)
        try:
            window = find_window(display, 'MuJoCo')
            wait_sim_time(env, SCREENSHOT_AT_S)
            image = screenshot(display, window, tmp_path / 'viewer.png')
        finally:
            stop_start_s = time.monotonic()
            stop_tree(process)
            exit_s = time.monotonic() - stop_start_s
            log.close()
    seen = robot_on_screen(image, m)
    print(f'viewer {image.shape[1]}x{image.shape[0]}: {seen}, span {seen.span_fraction:.2f} of '
          f'the height; launch stopped {exit_s:.1f} s after Ctrl-C; '
          f'screenshot {tmp_path / "viewer.png"}')
    assert seen.head_pixels >= MIN_HEAD_PIXELS, 'the head is not on screen'
    assert seen.leg_pixels >= MIN_LEG_PIXELS, 'the legs are not on screen'
    assert seen.feet_on_screen, 'the feet are below the window'
    assert seen.span_fraction >= MIN_SPAN_FRACTION
    with pytest.raises(LookupError, match='found 0 UI section title bars'):
        find_reset_button(image)  # the panels are a key away, not on screen
    output = (tmp_path / 'launch.log').read_text(errors='replace')
    assert 'cannot open the MuJoCo viewer' not in output


def _offscreen_frame(m: mujoco.MjModel, camera: mujoco.MjvCamera) -> np.ndarray:
    atlas = atlas_model.load_model()
    data = mujoco.MjData(atlas.model)
    atlas_model.reset_to_initial(atlas, data)
    with mujoco.Renderer(atlas.model, height=533, width=853) as renderer:
        renderer.update_scene(data, camera=camera)
        return renderer.render()


def test_the_check_tells_the_new_view_from_the_old_close_up(tmp_path: Path) -> None:
    """The viewer's camera before this change (MuJoCo's default free camera, a close-up of a
    shin) fails the check; the tracking camera configure_viewer_camera sets passes it."""
    atlas = atlas_model.load_model()
    m = atlas.model
    data = mujoco.MjData(m)
    atlas_model.reset_to_initial(atlas, data)
    old = mujoco.MjvCamera()
    mujoco.mjv_defaultCamera(old)
    new = mujoco.MjvCamera()
    configure_viewer_camera(new, m, data)
    figures = {}
    for name, camera in (('old', old), ('new', new)):
        figures[name] = robot_on_screen(_offscreen_frame(m, camera), m)
        print(f'{name} camera: {figures[name]}, span {figures[name].span_fraction:.2f}')
    assert not figures['old'].shows_whole_robot()
    assert figures['new'].shows_whole_robot()
