"""rviz.launch beside atlas.launch, under a real X server (Xvfb) with software OpenGL: the
robot model is drawn in the 3D view, and rviz reports no missing frame or robot_description.
Also the bad inputs: rviz without a display, and a model variant without a URDF.

Robot pixels are found from the model's material colours (support.xdisplay.material_mask)
inside rviz's 3D view (the area of its background colour); rviz draws the URDF's colours,
which are the MJCF's.
"""

from __future__ import annotations

import functools
import os
import shutil
import subprocess
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

import rosgraph
from test_viewer_window import CHROMA_TOLERANCE, MIN_BRIGHTNESS

from support.launch import wait_sim_time
from support.xdisplay import display_env, find_window, material_mask, screenshot, xvfb
from tutorial_atlas_control.processes import (
    free_local_port,
    ros_environment,
    stop_tree,
)
from tutorial_atlas_control.sim import model as atlas_model

#: rviz/atlas.rviz's background colour: the 3D view is where it shows.
BACKGROUND_RGB = (48, 48, 48)
#: The 3D view's rows and columns hold more background pixels than this.
MIN_VIEW_SIDE_PX = 100
#: Robot-coloured pixels in the 3D view at least. Measured on the 1280 x 800 screen: the head
#: about 1000 orange pixels, the legs and arms about 12000 blue; with tf:=false (no
#: robot_description, no TF) none of either. A quarter of the measured figures: a robot drawn
#: at half the size still passes, an empty view never does.
MIN_HEAD_PIXELS = 250
MIN_LEG_PIXELS = 3000
#: The grid's lines (rviz/atlas.rviz: 160, 160, 164 at half alpha) blend into the
#: background as neutral greys between the two: in the view they mean rviz has rendered
#: the scene. Measured: about 12 000 such pixels (62..125 grey); none before the first frame.
GRID_GREY_RANGE = (55, 165)
GRID_MAX_CHROMA = 4
MIN_GRID_PIXELS = 2000
#: Wall-clock guard (s) for rviz's first frames of the robot (software GL, a loaded machine).
RVIZ_DRAW_TIMEOUT_S = 120.0
#: Between two screenshots while waiting (s).
SCREENSHOT_PERIOD_S = 1.0
#: Lines of rviz's output in a failure's message.
LOG_TAIL_LINES = 30
#: Frames of an rviz crash's backtrace in a failure's message.
BACKTRACE_FRAMES = 25
RVIZ_BINARY = '/usr/lib/rviz/rviz'
#: rviz messages that would mean it cannot place or build the robot.
BAD_MESSAGES = ('robot_description', 'does not exist', 'No transform', 'Could not transform',
                'Fixed Frame', 'URDF')


def view_of(image: np.ndarray) -> np.ndarray | None:
    """rviz's 3D view in a screenshot (the area of its background colour); None if not shown."""
    background = np.all(image == BACKGROUND_RGB, axis=2)
    # Rows and columns mostly of background: the view, not the colour swatch in the panel.
    rows = np.nonzero(background.sum(axis=1) > MIN_VIEW_SIDE_PX)[0]
    cols = np.nonzero(background.sum(axis=0) > MIN_VIEW_SIDE_PX)[0]
    if not len(rows) or not len(cols):
        return None
    return image[rows[0]:rows[-1] + 1, cols[0]:cols[-1] + 1]


@functools.cache
def material_colours() -> tuple[np.ndarray, np.ndarray]:
    """The model's orange and blue (rgba): compiled once, not at every screenshot."""
    m = atlas_model.load_model().model
    return m.material('orange').rgba.copy(), m.material('blue').rgba.copy()


def robot_pixels(view: np.ndarray) -> tuple[int, int]:
    """(orange, blue) pixels in rviz's 3D view."""
    return tuple(int(material_mask(view, rgba, CHROMA_TOLERANCE, MIN_BRIGHTNESS).sum())
                 for rgba in material_colours())


def shows_robot(view: np.ndarray) -> bool:
    head, legs = robot_pixels(view)
    return head >= MIN_HEAD_PIXELS and legs >= MIN_LEG_PIXELS


def grid_pixels(view: np.ndarray) -> int:
    """Pixels of the view in the grid's blended greys."""
    pixels = view.astype(np.int16)
    chroma = pixels.max(axis=2) - pixels.min(axis=2)
    low, high = GRID_GREY_RANGE
    return int(((chroma <= GRID_MAX_CHROMA) & (pixels[..., 0] >= low)
                & (pixels[..., 0] <= high)).sum())


def shows_grid(view: np.ndarray) -> bool:
    return grid_pixels(view) >= MIN_GRID_PIXELS


def log_tail(path: Path, lines: int = LOG_TAIL_LINES) -> str:
    return '\n'.join(path.read_text(errors='replace').splitlines()[-lines:])


def crash_backtrace(ros_home: Path) -> str:
    """The backtrace of rviz's core dump under `ros_home` (roslaunch runs nodes there), or
    why there is none: rviz's own start-up crashes are rare and need their stack to fix."""
    cores = sorted(ros_home.glob('core*'))
    if not cores:
        return f'no core dump in {ros_home} (kernel.core_pattern is not "core"?)'
    if shutil.which('gdb') is None:
        return f'core dump {cores[0]}; install gdb for its backtrace'
    result = subprocess.run(['gdb', '-batch', '-nx', '-ex', 'bt', RVIZ_BINARY, str(cores[0])],
                            capture_output=True, text=True, timeout=120, check=False)
    # gdb shows the crashing frame on loading the core, then the whole stack.
    frames = list(dict.fromkeys(line for line in result.stdout.splitlines()
                                if line.startswith('#')))
    return f'core dump {cores[0]}, backtrace:\n' + '\n'.join(frames[:BACKTRACE_FRAMES])


def drawn_view(display: str, path: Path, drawn: Callable[[np.ndarray], bool],
               rviz: subprocess.Popen, rviz_log: Path, ros_home: Path) -> np.ndarray:
    """rviz's 3D view once `drawn` says so of it. Fails, with the end of rviz's output, if
    rviz.launch ends first or nothing is drawn within RVIZ_DRAW_TIMEOUT_S."""
    deadline = time.monotonic() + RVIZ_DRAW_TIMEOUT_S
    while True:
        view = view_of(screenshot(display, 'root', path))
        if view is not None and drawn(view):
            return view
        if rviz.poll() is not None:
            pytest.fail(f'rviz.launch ended (exit status {rviz.returncode}) before its view '
                        f'was drawn; screen {path}; its output ends:\n{log_tail(rviz_log)}\n'
                        f'{crash_backtrace(ros_home)}')
        if time.monotonic() > deadline:
            seen = 'no 3D view' if view is None else '3D view, not drawn'
            pytest.fail(f'rviz did not draw within {RVIZ_DRAW_TIMEOUT_S:.0f} s ({seen}); '
                        f'screen {path}; its output ends:\n{log_tail(rviz_log)}')
        time.sleep(SCREENSHOT_PERIOD_S)


#: rviz itself (Debian's 1.14.19 on Mesa's llvmpipe) crashed in this test four times, each
#: beside make test's loaded parallel part (load 8-10): twice at start-up, once with
#: "free(): invalid next size" in Mesa's buffer swap, once in LLVM compiling a shader.
#: Neither valgrind (6 min of it drawing the robot: no invalid access) nor 50 starts and
#: 2100 window resizes at load 5 reproduced it: rviz's launch runs with the machine's
#: attention, after the parallel part. It crashed once more there (in llvmpipe's rasterizer
#: threads, inside swrast_dri.so): every crash was in llvmpipe's own code (its threads, its
#: LLVM shader compiler), so rviz draws with Mesa's softpipe, which runs neither: 20 launches
#: beside a busy core, all drawn. MuJoCo's windows keep llvmpipe (never crashed).
RVIZ_GL = {'GALLIUM_DRIVER': 'softpipe'}


@pytest.mark.serial
@pytest.mark.parametrize('tf', [True, False], ids=['tf', 'no_tf'])
def test_rviz_shows_the_robot(tmp_path: Path, tf: bool) -> None:
    """With atlas.launch's TF, the robot in the 3D view; with tf:=false (no robot_description,
    no TF: the check's bad frame), none of its colours once the view is drawn."""
    with xvfb(tmp_path / 'xvfb.log') as display:
        port = free_local_port()
        env = ros_environment(port, tmp_path / 'ros_log',
                              base=dict(display_env(display), **RVIZ_GL))
        atlas_log = open(tmp_path / 'atlas.log', 'w')  # noqa: SIM115 - closed below
        rviz_log = open(tmp_path / 'rviz.log', 'w')  # noqa: SIM115 - closed below
        atlas = subprocess.Popen(
            ['roslaunch', '-p', str(port), 'tutorial_atlas_control', 'atlas.launch', 'gui:=false',
             'record:=false', f'tf:={str(tf).lower()}'], env=env, stdout=atlas_log,
            stderr=subprocess.STDOUT, start_new_session=True)
        rviz = None
        try:
            wait_sim_time(env, 1.0)
            # Core dumps on, in a ROS_HOME of the test's own: a crash of rviz leaves its stack.
            ros_home = tmp_path / 'rviz_home'
            ros_home.mkdir()
            rviz = subprocess.Popen(['prlimit', '--core=unlimited', 'roslaunch',
                                     'tutorial_atlas_control', 'rviz.launch'],
                                    env=dict(env, ROS_HOME=str(ros_home)), stdout=rviz_log,
                                    stderr=subprocess.STDOUT, start_new_session=True)
            find_window(display, 'RViz')
            # The robot once drawn; without TF (no robot_description) the view once rendered,
            # grid and all: a frame the robot would be in.
            view = drawn_view(display, tmp_path / 'rviz.png', shows_robot if tf else shows_grid,
                              rviz, tmp_path / 'rviz.log', ros_home)
        finally:
            if rviz is not None:
                stop_tree(rviz)
            stop_tree(atlas)
            atlas_log.close()
            rviz_log.close()
    head, legs = robot_pixels(view)
    output = (tmp_path / 'rviz.log').read_text(errors='replace')
    print(f'rviz (tf:={tf}): {head} orange and {legs} blue pixels in the 3D view; '
          f'screenshot {tmp_path / "rviz.png"}')
    assert 'OpenGL device: softpipe' in output  # RVIZ_GL taken
    if not tf:
        assert head < MIN_HEAD_PIXELS and legs < MIN_LEG_PIXELS
        return
    assert head >= MIN_HEAD_PIXELS
    assert legs >= MIN_LEG_PIXELS
    bad = [line for line in output.splitlines()
           if any(text in line for text in BAD_MESSAGES) and ('ERROR' in line or 'WARN' in line)]
    assert bad == []


def test_rviz_without_a_display_says_so_in_one_line(tmp_path: Path) -> None:
    env = dict(os.environ, ROS_LOG_DIR=str(tmp_path / 'ros_log'),
               ROS_MASTER_URI=f'http://localhost:{free_local_port()}')
    env.pop('DISPLAY', None)
    result = subprocess.run(['roslaunch', 'tutorial_atlas_control', 'rviz.launch'], env=env,
                            capture_output=True, text=True, timeout=120, check=False)
    assert result.returncode == 1
    errors = [line for line in result.stderr.splitlines() if line.strip()]
    # roslaunch's own fixed second line follows ours: "The traceback ... written to the log file".
    assert "environment variable 'DISPLAY' is not set" in errors[0]
    assert len(errors) == 2 and 'log file' in errors[1]
    assert 'Traceback' not in result.stderr


def test_model_variant_without_urdf_runs_without_tf(tmp_path: Path) -> None:
    variant = tmp_path / 'variant.xml'
    shutil.copy(atlas_model.MODEL_PATH, variant)
    port = free_local_port()
    env = dict(os.environ, ROS_MASTER_URI=f'http://localhost:{port}', ROS_HOSTNAME='localhost',
               ROS_LOG_DIR=str(tmp_path / 'ros_log'))
    log = open(tmp_path / 'atlas.log', 'w')  # noqa: SIM115 - closed below
    process = subprocess.Popen(
        ['roslaunch', '-p', str(port), 'tutorial_atlas_control', 'atlas.launch', 'gui:=false',
         'record:=false', f'model:={variant}'], env=env, stdout=log, stderr=subprocess.STDOUT,
        start_new_session=True)
    try:
        wait_sim_time(env, 1.0)  # the simulator runs
        master = rosgraph.Master('/test_variant', master_uri=env['ROS_MASTER_URI'])
        publishers = dict(master.getSystemState()[0])
        has_description = master.hasParam('/robot_description')
    finally:
        stop_tree(process)
        log.close()
    output = (tmp_path / 'atlas.log').read_text(errors='replace')
    warnings = [line for line in output.splitlines() if 'TF is off' in line]
    assert len(warnings) == 1, output
    assert (f'the model {variant} has no URDF beside it '
            f'({tmp_path / "variant.urdf"} does not exist)') in warnings[0]
    assert '/tf' not in publishers
    assert not has_description
    assert '/clock' in publishers
