"""A private X server (Xvfb) for the tests that open windows: start and stop it, find a
window on it, capture the window's pixels and read them.

Each test starts its own Xvfb on a free display number, so a GUI test never draws on the
user's display and several can run at once. Windows are found with xdotool and captured
with ImageMagick's `import` (Debian packages xvfb, xdotool, imagemagick: tools/setup.sh).
"""

from __future__ import annotations

import io
import os
import shutil
import subprocess
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest

#: The screen users of the viewer and rviz issues tried: 1280 x 800, 24-bit colour.
SCREEN = '1280x800x24'
#: Display numbers tried for the private X server.
DISPLAYS = range(70, 200)
#: Wall-clock guards (s): Xvfb coming up, a window appearing (a GUI launch on a loaded
#: machine with software OpenGL), one capture.
START_TIMEOUT_S = 20.0
WINDOW_TIMEOUT_S = 180.0
CAPTURE_TIMEOUT_S = 60.0
POLL_PERIOD_S = 0.5
STOP_TIMEOUT_S = 10.0
TOOLS = ('Xvfb', 'xdotool', 'import')

#: MuJoCo's default UI theme: a section title's top row is red (R > 2 G, R > 2 B, R > 100)
#: and an enabled button's outline is (153, 102, 102), i.e. (0.6, 0.4, 0.4).
BUTTON_OUTLINE_RGB = (153, 102, 102)
COLOUR_TOLERANCE = 12
#: A title bar or a button outline is a horizontal run at least this long (px).
MIN_TITLE_RUN_PX = 100
MIN_BUTTON_RUN_PX = 30
#: The title bars counted down the viewer's left panel: File, Option, Simulation.
SIMULATION_SECTION_INDEX = 2
#: The cross save_png draws at a marked point: half its arm (px) and its colour.
MARK_HALF_PX = 8
MARK_RGB = (0, 255, 0)


def missing_tools() -> list[str]:
    """The X tools not on PATH: a test skips rather than fail on a machine without them."""
    return [tool for tool in TOOLS if shutil.which(tool) is None]


def skip_module_unless_launchable() -> None:
    """Skip the calling test module unless the X tools, roslaunch and the workspace are there."""
    if missing_tools():
        pytest.skip(f'needs {", ".join(missing_tools())} (tools/setup.sh installs '
                    'xvfb, xdotool and imagemagick)', allow_module_level=True)
    if shutil.which('roslaunch') is None:
        pytest.skip('roslaunch is not on PATH (source env.sh)', allow_module_level=True)
    pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')


def _socket(number: int) -> Path:
    return Path(f'/tmp/.X11-unix/X{number}')


def _free_displays() -> Iterator[int]:
    """Display numbers no X server holds now (no lock file, no socket)."""
    for number in DISPLAYS:
        if not Path(f'/tmp/.X{number}-lock').exists() and not _socket(number).exists():
            yield number


def _stop(process: subprocess.Popen) -> None:
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout=STOP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def _lock_pid(number: int) -> int | None:
    """The process holding display `number` (its lock file), None if none or unreadable."""
    try:
        return int(Path(f'/tmp/.X{number}-lock').read_text().strip())
    except (OSError, ValueError):
        return None


def answers(display: str) -> bool:
    """Whether the X server at `display` accepts a client (xdotool opens it)."""
    try:
        return subprocess.run(['xdotool', 'getdisplaygeometry'],
                              env=dict(os.environ, DISPLAY=display), capture_output=True,
                              timeout=CAPTURE_TIMEOUT_S, check=False).returncode == 0
    except subprocess.TimeoutExpired:
        return False


def _serving(process: subprocess.Popen, number: int) -> bool:
    """Whether our Xvfb `process` holds display `number` and answers there.

    Its socket file alone is not enough: another test's Xvfb may hold the number (ours then
    exits, but may not have yet), and a viewer started on a display whose server did not
    answer yet ran headless ("no X server answers").
    """
    return (process.poll() is None and _socket(number).exists()
            and _lock_pid(number) == process.pid and answers(f':{number}'))


@contextmanager
def xvfb(log_path: Path, screen: str = SCREEN) -> Iterator[str]:
    """Yield the DISPLAY (':N') of a fresh Xvfb logging to `log_path`, once it answers
    there; stop it afterwards.

    Another test (or another checkout's tests) may take a free number between the check
    and Xvfb's start; Xvfb then exits at once and the next free number is tried.
    """
    missing = missing_tools()
    if missing:
        pytest.skip(f'needs {", ".join(missing)} (tools/setup.sh installs xvfb, xdotool and '
                    'imagemagick)')
    with open(log_path, 'w') as log:
        for number in _free_displays():
            process = subprocess.Popen(
                # -noreset: by default an X server resets when its last client leaves, and a
                # client connecting meanwhile is refused ("Failed to open display"): a
                # viewer starting while the test's xdotool polls the display.
                ['Xvfb', f':{number}', '-screen', '0', screen, '-nolisten', 'tcp', '-noreset'],
                stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
            try:
                deadline = time.monotonic() + START_TIMEOUT_S
                while process.poll() is None and not _serving(process, number):
                    if time.monotonic() > deadline:
                        pytest.fail(f'Xvfb :{number} did not start within '
                                    f'{START_TIMEOUT_S:.0f} s; see {log_path}')
                    time.sleep(0.05)
                if process.poll() is None:
                    yield f':{number}'
                    return
            finally:
                _stop(process)
        pytest.fail(f'no free X display in :{DISPLAYS.start}..:{DISPLAYS.stop - 1}; '
                    f'see {log_path}')


def display_env(display: str) -> dict[str, str]:
    """This environment for a GUI process on `display`: software OpenGL (Xvfb has no GPU),
    and without env.sh's headless OSMesa choice, which would keep MuJoCo off the display."""
    env = dict(os.environ, DISPLAY=display, LIBGL_ALWAYS_SOFTWARE='1')
    for name in ('MUJOCO_GL', 'PYOPENGL_PLATFORM'):
        env.pop(name, None)
    return env


def find_window(display: str, name: str, timeout_s: float = WINDOW_TIMEOUT_S) -> str:
    """The id of the first window whose title contains `name`, once it exists."""
    env = dict(os.environ, DISPLAY=display)
    deadline = time.monotonic() + timeout_s
    while True:
        try:
            found = subprocess.run(['xdotool', 'search', '--name', name], env=env,
                                   capture_output=True, text=True, check=False,
                                   timeout=CAPTURE_TIMEOUT_S).stdout.split()
        except subprocess.TimeoutExpired:  # a search stuck on a window being destroyed
            found = []
        if found:
            return found[0]
        if time.monotonic() > deadline:
            pytest.fail(f'no window named {name!r} on {display} within {timeout_s:.0f} s')
        time.sleep(POLL_PERIOD_S)


class CaptureError(AssertionError):
    """`import` could not read a window's pixels (its exit status and stderr)."""


def screenshot(display: str, window: str, path: Path | None = None) -> np.ndarray:
    """The pixels of `window` ('root': the whole screen), (height, width, 3) uint8 RGB.

    With `path`, the capture is also kept there as a PNG, for a person to look at when a
    test fails. Raises CaptureError when `import` fails: reading a window the X server is
    changing (the viewer's panels appearing) fails now and then ("unable to read X window
    image"), and a wait for what the window shows may take that as "not yet".
    """
    from PIL import Image

    capture = subprocess.run(['import', '-display', display, '-window', window, 'png:-'],
                             check=False, capture_output=True, timeout=CAPTURE_TIMEOUT_S)
    if capture.returncode != 0:
        raise CaptureError(f'import could not capture window {window} on {display} '
                           f'(exit {capture.returncode}): {capture.stderr.decode().strip()}')
    png = capture.stdout
    if path is not None:
        path.write_bytes(png)
    with Image.open(io.BytesIO(png)) as image:
        return np.asarray(image.convert('RGB'))


def save_png(pixels: np.ndarray, path: Path, mark: tuple[int, int] | None = None) -> None:
    """Write `pixels` as a PNG, with a cross at `mark` (x, y): where a test clicked."""
    from PIL import Image

    image = pixels.copy()
    if mark is not None:
        x, y = mark
        image[max(0, y - MARK_HALF_PX):y + MARK_HALF_PX + 1, x] = MARK_RGB
        image[y, max(0, x - MARK_HALF_PX):x + MARK_HALF_PX + 1] = MARK_RGB
    Image.fromarray(image).save(path)


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


def _runs(mask_row: np.ndarray) -> list[tuple[int, int]]:
    """(start, length) of the runs of True in a boolean row."""
    padded = np.concatenate(([False], mask_row, [False])).astype(np.int8)
    edges = np.flatnonzero(np.diff(padded))
    return [(int(a), int(b - a)) for a, b in zip(edges[::2], edges[1::2])]


def _longest_run(mask_row: np.ndarray) -> tuple[int, int]:
    return max(_runs(mask_row), key=lambda run: run[1], default=(0, 0))


def find_reset_button(pixels: np.ndarray) -> tuple[int, int]:
    """Window coordinates (x, y) of the middle of the MuJoCo viewer's "Reset" button.

    MuJoCo draws its UI itself (no X widgets to query), so the button is found from the
    layout its simulate UI has had since 2.x: the left panel stacks sections whose title
    bars are a red gradient (File, Option, Simulation, ...); in the Simulation section of a
    *passive* viewer the first enabled button is "Reset" (the Pause/Run switch above it is
    greyed out), and enabled buttons are outlined in the theme's button colour. The
    button's top and bottom outline rows are the first two long runs of that colour below
    the third title bar.

    Raises:
        LookupError: the layout is not that one (e.g. the UI is not drawn yet).
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
