"""A private X server (Xvfb) for tests that open windows, screenshots of it, and the
roslaunch helpers those tests share.

Each test starts its own Xvfb on a free display number and stops it; windows are found with
xdotool and captured with ImageMagick's `import` (Debian packages xvfb, xdotool, imagemagick).
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

#: The screen users of the issue tried: 1280 x 800, 24-bit colour.
SCREEN = '1280x800x24'
#: Display numbers tried, and how long Xvfb may take to come up (s).
DISPLAYS = range(70, 200)
START_TIMEOUT_S = 20.0
#: Longest wait (s, wall) for a window or for sim time.
WALL_TIMEOUT_S = 180.0


def _free_display() -> int:
    for number in DISPLAYS:
        if not Path(f'/tmp/.X{number}-lock').exists() and not Path(f'/tmp/.X11-unix/X{number}').exists():
            return number
    raise AssertionError(f'no free X display number in {DISPLAYS}')


@contextmanager
def xvfb() -> Iterator[str]:
    """Yield the DISPLAY of a fresh Xvfb; stop it afterwards."""
    for tool in ('Xvfb', 'xdotool', 'import'):
        if shutil.which(tool) is None:
            pytest.skip(f'{tool} is not installed; run `make setup`')
    number = _free_display()
    process = subprocess.Popen(['Xvfb', f':{number}', '-screen', '0', SCREEN, '-nolisten', 'tcp'],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                               start_new_session=True)
    try:
        deadline = time.monotonic() + START_TIMEOUT_S
        while not Path(f'/tmp/.X11-unix/X{number}').exists():
            assert process.poll() is None, f'Xvfb :{number} exited with {process.returncode}'
            assert time.monotonic() < deadline, f'Xvfb :{number} did not start'
            time.sleep(0.1)
        yield f':{number}'
    finally:
        process.terminate()
        try:
            process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def find_window(display: str, name: str, timeout_s: float = WALL_TIMEOUT_S) -> str:
    """The id of the first window whose title contains `name`."""
    env = dict(os.environ, DISPLAY=display)
    deadline = time.monotonic() + timeout_s
    while True:
        found = subprocess.run(['xdotool', 'search', '--name', name], env=env,
                               capture_output=True, text=True, check=False).stdout.split()
        if found:
            return found[0]
        assert time.monotonic() < deadline, f'no window named {name!r} on {display}'
        time.sleep(0.5)


def screenshot(display: str, window: str, path: Path) -> np.ndarray:
    """Capture `window` ('root' for the screen) to the PNG `path`; return its RGB pixels."""
    from PIL import Image

    subprocess.run(['import', '-display', display, '-window', window, str(path)],
                   check=True, capture_output=True, timeout=60)
    with Image.open(path) as image:
        return np.asarray(image.convert('RGB'))


def material_mask(image: np.ndarray, rgba: np.ndarray, chroma_tolerance: float,
                  min_brightness: float) -> np.ndarray:
    """Pixels drawn in a material's colour, whatever the lighting.

    Light scales a surface's colour up or down but keeps its proportions (chromaticity,
    r : g : b); pixels whose proportions are within `chroma_tolerance` of the material's,
    and brighter than `min_brightness` (0..1; near-black pixels have no reliable hue),
    count. Grey materials cannot be told from the grey floor this way, so tests use the
    saturated ones (the orange head, the blue legs and arms).
    """
    pixels = image.astype(float) / 255.0
    total = pixels.sum(axis=2)
    chroma = pixels / np.maximum(total, 1e-6)[..., None]
    target = np.asarray(rgba[:3], dtype=float) / float(np.sum(rgba[:3]))
    close = np.linalg.norm(chroma - target, axis=2) < chroma_tolerance
    return close & (total / 3.0 > min_brightness)


def launch_env(display: str, tmp_path: Path, port: int) -> dict[str, str]:
    """The environment of a launch on `display` with software OpenGL and its own master."""
    env = dict(os.environ, DISPLAY=display, LIBGL_ALWAYS_SOFTWARE='1',
               ROS_MASTER_URI=f'http://localhost:{port}', ROS_HOSTNAME='localhost',
               ROS_LOG_DIR=str(tmp_path / 'ros_log'))
    for name in ('MUJOCO_GL', 'PYOPENGL_PLATFORM'):  # env.sh's headless choice: not here
        env.pop(name, None)
    return env


WAIT_SIM_TIME = '''
import sys, rospy
from rosgraph_msgs.msg import Clock
rospy.init_node('wait_sim_time', anonymous=True, disable_signals=True)
target = float(sys.argv[1])
while rospy.wait_for_message('/clock', Clock, timeout=120).clock.to_sec() < target:
    pass
'''


def wait_sim_time(env: dict[str, str], seconds: float) -> None:
    """Until the launch's /clock reaches `seconds` of sim time."""
    subprocess.run([sys.executable, '-c', WAIT_SIM_TIME, str(seconds)], env=env, check=True,
                   timeout=WALL_TIMEOUT_S, capture_output=True)


def stop_launch(process: subprocess.Popen) -> float:
    """SIGINT the launch as Ctrl-C would; return how long it took to exit (s)."""
    start = time.monotonic()
    os.killpg(process.pid, signal.SIGINT)
    try:
        process.wait(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()
    return time.monotonic() - start
