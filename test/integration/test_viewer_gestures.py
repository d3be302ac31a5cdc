"""The MuJoCo viewer's Reset (key, button, Shift+Ctrl+R) and pause (Space), under Xvfb.

`atlas.launch gui:=true` runs on a private X server and ROS master; xdotool presses keys in
the viewer's window and clicks its Reset button (found from the window's pixels, see
support.xdisplay.find_reset_button); viewer_probe.py, a ROS node in its own process,
ragdolls the robot until it lies down and reports what the gesture did. A reset must be the
node's reset_world: the pelvis back at the spawn height and held there (pinned) for the
watch window, /clock never going backwards, /atlas/sim_config carrying the new reset time
(in sim time, not 0). The window opens with MuJoCo's panels hidden; the button test shows
the left one with Tab first, as a user would.

Needs Xvfb, xdotool and ImageMagick (tools/setup.sh installs them) and `source ./env.sh`.
Wall time about 90 s for the module (one simulator for all gestures).
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from support import xdisplay
from tutorial_atlas_control.processes import free_local_port, ros_environment, stop_tree
from tutorial_atlas_control.sim.model import SPAWN_HEIGHT_M

xdisplay.skip_module_unless_launchable()

PROBE = Path(__file__).resolve().parent / 'viewer_probe.py'
WINDOW_NAME = 'MuJoCo'
#: The screen the Reset button's layout (xdisplay.find_reset_button) is read on.
SCREEN = '1280x1024x24'
SPAWN_TOLERANCE_M = 0.001
#: The probe's pinned-height window holds ~78 odometry samples at 100 Hz; far fewer means
#: the height was not watched over the window.
MIN_PINNED_SAMPLES = 30
PINNED_WINDOW_TEXT = 'the 0.02-0.8 s after it (torso pinned 1 s)'
#: Wall-clock bounds (s).
PROBE_TIMEOUT_S = 180.0
UI_DRAWN_TIMEOUT_S = 30.0


@dataclass
class Viewer:
    env: dict[str, str]
    display: str
    window: str
    log_dir: Path


@pytest.fixture(scope='module')
def viewer(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Viewer]:
    log_dir = tmp_path_factory.mktemp('viewer')
    with xdisplay.xvfb(log_dir / 'xvfb.log', SCREEN) as display:
        port = free_local_port()
        env = ros_environment(port, log_dir / 'ros_log', base=xdisplay.display_env(display))
        log = open(log_dir / 'atlas_launch.log', 'w')  # noqa: SIM115 - closed below
        launch = subprocess.Popen(
            ['roslaunch', '-p', str(port), 'tutorial_atlas_control', 'atlas.launch',
             'gui:=true', 'record:=false'], env=env, stdout=log, stderr=subprocess.STDOUT,
            start_new_session=True)
        try:
            window = xdisplay.find_window(display, WINDOW_NAME)
            yield Viewer(env, display, window, log_dir)
            assert launch.poll() is None, f'atlas.launch exited; see {log.name}'
        finally:
            stop_tree(launch)
            log.close()


def run_probe(viewer: Viewer, scenario: str, gesture: list[str]) -> dict[str, object]:
    result = subprocess.run([sys.executable, str(PROBE), scenario, json.dumps(gesture)],
                            env=viewer.env, capture_output=True, text=True,
                            timeout=PROBE_TIMEOUT_S, check=False)
    assert result.returncode == 0, f'{result.stdout}\n{result.stderr}'
    report = json.loads(result.stdout.strip().splitlines()[-1])
    assert 'error' not in report, f'{report["error"]}; see {viewer.log_dir}'
    return report


def assert_reset_world(report: dict[str, object]) -> None:
    assert report['collapsed_z_m'] < 0.5
    # sim time kept: the reset happened at the current sim time, not at a rewound 0
    assert report['reset_after_s'] > report['reset_before_s']
    assert report['reset_after_s'] >= report['gesture_clock_s']
    heights = report['pinned_heights_m']
    assert len(heights) >= MIN_PINNED_SAMPLES, heights
    worst = max(abs(z - SPAWN_HEIGHT_M) for z in heights)
    print(f'\nreset at {report["reset_after_s"]:.3f} s '
          f'(gesture at {report["gesture_clock_s"]:.3f} s, '
          f'pelvis was at {report["collapsed_z_m"]:.3f} m): {len(heights)} heights over '
          f'{PINNED_WINDOW_TEXT}, at most {worst * 1000:.3f} mm from the spawn height; '
          f'{report["clock_count"]} /clock messages, {report["clock_backwards"]} backwards')
    assert worst <= SPAWN_TOLERANCE_M, (
        f'pelvis {min(heights):.4f}..{max(heights):.4f} m after the reset, spawn '
        f'{SPAWN_HEIGHT_M:.4f} m')
    assert report['clock_backwards'] == 0


def test_reset_key_is_reset_world(viewer: Viewer) -> None:
    report = run_probe(viewer, 'reset', ['xdotool', 'key', '--window', viewer.window, 'BackSpace'])
    assert_reset_world(report)


def test_shift_ctrl_r_is_reset_world(viewer: Viewer) -> None:
    report = run_probe(viewer, 'reset',
                       ['xdotool', 'key', '--window', viewer.window, 'shift+ctrl+r'])
    assert_reset_world(report)


def test_reset_button_is_reset_world(viewer: Viewer) -> None:
    subprocess.run(['xdotool', 'key', '--window', viewer.window, 'Tab'], env=viewer.env,
                   check=True)  # the left panel, hidden when the window opens
    deadline = time.monotonic() + UI_DRAWN_TIMEOUT_S
    while True:
        try:  # while the panel appears, a capture may fail: not drawn yet, like no button
            pixels = xdisplay.screenshot(viewer.display, viewer.window)
        except xdisplay.CaptureError:
            if time.monotonic() > deadline:
                raise
            time.sleep(1.0)
            continue
        try:
            x, y = xdisplay.find_reset_button(pixels)
            break
        except LookupError:
            if time.monotonic() > deadline:
                xdisplay.save_png(pixels, viewer.log_dir / 'no_reset_button.png')
                raise
            time.sleep(1.0)
    xdisplay.save_png(pixels, viewer.log_dir / 'reset_button.png', (x, y))
    print(f'\nReset button at ({x}, {y}); screenshot {viewer.log_dir / "reset_button.png"}')
    report = run_probe(viewer, 'reset', ['xdotool', 'mousemove', '--window', viewer.window,
                                         str(x), str(y), 'click', '1'])
    assert_reset_world(report)


def test_space_pauses_and_unpauses_physics(viewer: Viewer) -> None:
    report = run_probe(viewer, 'pause', ['xdotool', 'key', '--window', viewer.window, 'space'])
    assert report['paused_until_s'] == report['paused_at_s'], 'sim time went on while paused'
    assert report['clock_backwards'] == 0
