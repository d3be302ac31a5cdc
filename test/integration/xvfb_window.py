"""A private X server (Xvfb) and the MuJoCo viewer window in it, driven with xdotool.

Finding the viewer's "Reset" button: MuJoCo draws its UI itself (no X widgets to query), so
the test reads the window's pixels (`import -window ID rgb:-`) and uses the layout MuJoCo's
simulate UI has had since 2.x: the left panel stacks sections whose title bars are a red
gradient (File, Option, Simulation, ...); in the Simulation section of a *passive* viewer
the first enabled button is "Reset" (the Pause/Run switch above it is greyed out), and
enabled buttons are outlined in the theme's button colour. The button's top and bottom
outline rows are the first two long runs of that colour below the third title bar; the
click goes to their middle. A screenshot with the point marked is saved next to the logs.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import time
from pathlib import Path

import numpy as np

#: Display numbers tried for the private X server.
FIRST_DISPLAY = 90
LAST_DISPLAY = 199
SCREEN = '1280x1024x24'
#: Wall-clock bounds (s).
XVFB_START_TIMEOUT_S = 10.0
WINDOW_TIMEOUT_S = 90.0
#: MuJoCo's default UI theme: a section title's top row is this red (R > 2 G, R > 2 B, R > 100)
#: and an enabled button's outline is (153, 102, 102), i.e. (0.6, 0.4, 0.4).
BUTTON_OUTLINE_RGB = (153, 102, 102)
COLOUR_TOLERANCE = 12
#: A title bar or a button outline is a horizontal run at least this long (px).
MIN_TITLE_RUN_PX = 100
MIN_BUTTON_RUN_PX = 30
#: The title bars counted down the left panel: File, Option, Simulation.
SIMULATION_SECTION_INDEX = 2

TOOLS = ('Xvfb', 'xdotool', 'import')


def missing_tools() -> list[str]:
    return [tool for tool in TOOLS if shutil.which(tool) is None]


def _display_free(number: int) -> bool:
    return not (Path(f'/tmp/.X{number}-lock').exists()
                or Path(f'/tmp/.X11-unix/X{number}').exists())


class Xvfb:
    """`Xvfb :N` on the first free display number from FIRST_DISPLAY; close() stops it."""

    def __init__(self, log_path: Path) -> None:
        self._log = open(log_path, 'w')  # noqa: SIM115 - closed in close()
        for number in range(FIRST_DISPLAY, LAST_DISPLAY + 1):
            if not _display_free(number):
                continue
            process = subprocess.Popen(
                ['Xvfb', f':{number}', '-screen', '0', SCREEN, '-nolisten', 'tcp'],
                stdout=self._log, stderr=subprocess.STDOUT, start_new_session=True)
            deadline = time.monotonic() + XVFB_START_TIMEOUT_S
            while process.poll() is None and time.monotonic() < deadline:
                if Path(f'/tmp/.X11-unix/X{number}').exists():
                    self.process, self.display = process, f':{number}'
                    return
                time.sleep(0.05)
            process.kill()  # lost a race for this display, or it failed: try the next
            process.wait()
        self._log.close()
        raise RuntimeError(f'no free X display in :{FIRST_DISPLAY}..:{LAST_DISPLAY}; '
                           f'see {log_path}')

    def env(self) -> dict[str, str]:
        """The environment of a GUI process on this display (GLFW, Mesa's llvmpipe)."""
        env = dict(os.environ, DISPLAY=self.display, MUJOCO_GL='glfw')
        env.pop('PYOPENGL_PLATFORM', None)
        return env

    def close(self) -> None:
        if self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self._log.close()


def xdotool(display: str, *args: str) -> str:
    result = subprocess.run(['xdotool', *args], env=dict(os.environ, DISPLAY=display),
                            capture_output=True, text=True, timeout=WINDOW_TIMEOUT_S,
                            check=True)
    return result.stdout


def wait_for_window(display: str, name: str) -> str:
    """The id of the first window whose title matches `name` (xdotool search --sync)."""
    return xdotool(display, 'search', '--sync', '--name', name).split()[0]


def window_size(display: str, window: str) -> tuple[int, int]:
    out = xdotool(display, 'getwindowgeometry', '--shell', window)
    values = dict(line.split('=', 1) for line in out.split() if '=' in line)
    return int(values['WIDTH']), int(values['HEIGHT'])


def capture(display: str, window: str) -> np.ndarray:
    """The window's pixels, (height, width, 3) uint8."""
    width, height = window_size(display, window)
    raw = subprocess.run(['import', '-window', window, '-depth', '8', 'rgb:-'],
                         env=dict(os.environ, DISPLAY=display), capture_output=True,
                         timeout=WINDOW_TIMEOUT_S, check=True).stdout
    return np.frombuffer(raw, np.uint8)[:width * height * 3].reshape(height, width, 3)


def save_png(pixels: np.ndarray, path: Path, mark: tuple[int, int] | None = None) -> None:
    """Write `pixels` as a PNG (via ImageMagick), with a green cross at `mark` (x, y)."""
    image = pixels.copy()
    if mark is not None:
        x, y = mark
        image[max(0, y - 8):y + 9, x] = (0, 255, 0)
        image[y, max(0, x - 8):x + 9] = (0, 255, 0)
    height, width, _ = image.shape
    subprocess.run(['convert', '-size', f'{width}x{height}', '-depth', '8', 'rgb:-', str(path)],
                   input=image.tobytes(), timeout=60, check=True)


def _runs(mask_row: np.ndarray) -> list[tuple[int, int]]:
    """(start, length) of the runs of True in a boolean row."""
    padded = np.concatenate(([False], mask_row, [False])).astype(np.int8)
    edges = np.flatnonzero(np.diff(padded))
    return [(int(a), int(b - a)) for a, b in zip(edges[::2], edges[1::2])]


def _longest_run(mask_row: np.ndarray) -> tuple[int, int]:
    return max(_runs(mask_row), key=lambda run: run[1], default=(0, 0))


def find_reset_button(pixels: np.ndarray) -> tuple[int, int]:
    """Window coordinates (x, y) of the middle of the viewer's "Reset" button.

    Raises:
        LookupError: the layout is not the one described in this module's docstring.
    """
    rgb = pixels.astype(np.int32)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    left = pixels.shape[1] // 2  # the left panel lies in the window's left half
    title = (r > 100) & (r > 2 * g) & (r > 2 * b)
    title_rows = [y for y in range(pixels.shape[0])
                  if _longest_run(title[y, :left])[1] >= MIN_TITLE_RUN_PX]
    tops = [y for i, y in enumerate(title_rows) if i == 0 or title_rows[i - 1] != y - 1]
    if len(tops) <= SIMULATION_SECTION_INDEX:
        raise LookupError(f'found {len(tops)} UI section title bars, expected at least '
                          f'{SIMULATION_SECTION_INDEX + 1}')
    section_top = tops[SIMULATION_SECTION_INDEX]
    start = next(y for y in title_rows if y >= section_top)
    while start + 1 in title_rows:
        start += 1
    outline = (np.abs(rgb - np.array(BUTTON_OUTLINE_RGB)) <= COLOUR_TOLERANCE).all(axis=2)
    edges = []
    for y in range(start + 1, pixels.shape[0]):
        x0, length = _longest_run(outline[y, :left])
        if length >= MIN_BUTTON_RUN_PX:
            if edges and y == edges[-1][0] + 1:
                continue  # a thick outline: one edge
            edges.append((y, x0, length))
            if len(edges) == 2:
                break
    if len(edges) < 2:
        raise LookupError('no enabled button below the Simulation title bar')
    (top, x0, length), (bottom, _, _) = edges
    return x0 + length // 2, (top + bottom) // 2
