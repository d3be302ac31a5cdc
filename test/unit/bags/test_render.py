"""Offscreen rendering of recorded runs: frames show the robot, videos get written, errors."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import imageio.v3 as iio
import numpy as np
import pytest
from PIL import Image

from support.synthetic_bags import (
    STANDING_HEIGHT_M,
    joint_state,
    odometry,
    write_bag,
    write_run_bag,
)
from tutorial_atlas_control.bags.reader import read_bag
from tutorial_atlas_control.bags.render import (
    RenderError,
    RunStates,
    StateRenderer,
    check_output_path,
    parse_size,
    render_states,
    states_from_bag,
)
from tutorial_atlas_control.cli.analyze_bag import main as analyze_main
from tutorial_atlas_control.joints import NUM_JOINTS

SCRIPT = Path(__file__).resolve().parents[3] / 'scripts' / 'analyze_bag.py'
UPRIGHT = np.array([1.0, 0.0, 0.0, 0.0])
#: Lying face down: 90 degrees about the pelvis y axis.
FACE_DOWN = np.array([math.cos(math.pi / 4), 0.0, math.sin(math.pi / 4), 0.0])
SMALL = (160, 120)


def falling_states(frames: int = 4) -> RunStates:
    """The pelvis drops from standing height to 0.25 m while tipping over."""
    share = np.linspace(0.0, 1.0, frames)
    position = np.zeros((frames, 3))
    position[:, 2] = STANDING_HEIGHT_M + share * (0.25 - STANDING_HEIGHT_M)
    angle = share * math.pi / 2
    quat = np.column_stack([np.cos(angle / 2), np.zeros(frames), np.sin(angle / 2),
                            np.zeros(frames)])
    return RunStates(share, position, quat, np.zeros((frames, NUM_JOINTS)))


def orange_pixels(frame: np.ndarray) -> np.ndarray:
    """Mask of the head's orange (the model's only orange material, rgb 0.91 0.44 0.03)."""
    red, green, blue = (frame[..., channel].astype(int) for channel in range(3))
    return (red > 150) & (green > 50) & (green < 150) & (blue < 80)


@pytest.fixture(scope='module')
def standing_and_fallen() -> tuple[np.ndarray, np.ndarray]:
    with StateRenderer(*SMALL) as renderer:
        standing = renderer.render(np.array([0.0, 0.0, STANDING_HEIGHT_M]), UPRIGHT,
                                   np.zeros(NUM_JOINTS))
        fallen = renderer.render(np.array([0.0, 0.0, 0.25]), FACE_DOWN, np.zeros(NUM_JOINTS))
    return standing, fallen


def test_frame_shows_the_robot(standing_and_fallen: tuple[np.ndarray, np.ndarray]) -> None:
    standing, _ = standing_and_fallen
    assert standing.shape == (SMALL[1], SMALL[0], 3) and standing.dtype == np.uint8
    assert len(np.unique(standing.reshape(-1, 3), axis=0)) > 100  # not blank
    assert orange_pixels(standing).sum() > 10  # the head is in view


def test_robot_pixels_move_when_it_falls(
        standing_and_fallen: tuple[np.ndarray, np.ndarray]) -> None:
    standing, fallen = standing_and_fallen
    assert np.abs(standing.astype(int) - fallen.astype(int)).mean() > 3.0
    rows_standing = np.nonzero(orange_pixels(standing))[0]
    rows_fallen = np.nonzero(orange_pixels(fallen))[0]
    assert len(rows_fallen) > 10
    # The head goes down the image by a good part of its height.
    assert rows_fallen.mean() - rows_standing.mean() > 0.15 * SMALL[1]


def test_renderer_is_a_closing_context_manager() -> None:
    with StateRenderer(32, 32) as renderer:
        pass
    with pytest.raises(RenderError, match='the renderer is closed'):
        renderer.render(np.zeros(3), UPRIGHT, np.zeros(NUM_JOINTS))
    renderer.close()  # idempotent


def test_larger_than_the_model_offscreen_buffer_is_fine() -> None:
    with StateRenderer(2000, 1100) as renderer:
        frame = renderer.render(np.array([0.0, 0.0, STANDING_HEIGHT_M]), UPRIGHT,
                                np.zeros(NUM_JOINTS))
    assert frame.shape == (1100, 2000, 3)


def test_mp4_is_written(tmp_path: Path) -> None:
    result = render_states(falling_states(), tmp_path / 'fall.mp4', fps=10, size=(64, 48),
                           progress=False)
    assert result.frames == 4 and result.path.stat().st_size > 0
    frames = iio.imread(result.path, index=None)
    assert frames.shape == (4, 48, 64, 3)


def test_gif_is_written(tmp_path: Path) -> None:
    result = render_states(falling_states(), tmp_path / 'fall.gif', fps=10, size=(64, 48),
                           progress=False)
    with Image.open(result.path) as gif:
        assert gif.n_frames == 4 and gif.size == (64, 48)
        assert gif.info['duration'] == 100


def test_states_are_sampled_at_the_frame_times(tmp_path: Path) -> None:
    """Odometry interpolated, joint states held: pelvis falls from 1.5 s in run_records."""
    bag = write_run_bag(tmp_path / 'run.bag', 3.0, with_imu=False, fall_time_s=1.5)
    states = states_from_bag(read_bag(bag), fps=10)
    assert len(states) == 30  # 0.0 .. 2.9 s (odometry ends at 2.99 s)
    np.testing.assert_allclose(np.diff(states.t_s), 0.1)
    assert states.pelvis_position_m[0, 2] == pytest.approx(STANDING_HEIGHT_M)
    assert states.pelvis_position_m[-1, 2] < 0.6
    np.testing.assert_allclose(np.linalg.norm(states.pelvis_quat_wxyz, axis=1), 1.0)
    assert states.joint_position_rad.shape == (30, NUM_JOINTS)


def test_pose_between_odometry_samples_is_interpolated(tmp_path: Path) -> None:
    bag = write_bag(tmp_path / 'x.bag', [
        odometry(0.0, 0.9), odometry(0.1, 0.5),
        joint_state(0.0, np.zeros(NUM_JOINTS)), joint_state(0.1, np.ones(NUM_JOINTS))])
    states = states_from_bag(read_bag(bag), fps=20)
    np.testing.assert_allclose(states.pelvis_position_m[:, 2], [0.9, 0.7, 0.5])
    np.testing.assert_array_equal(states.joint_position_rad[:, 0], [0.0, 0.0, 1.0])


def test_bag_without_odometry_cannot_be_rendered(tmp_path: Path) -> None:
    bag = write_bag(tmp_path / 'x.bag', [joint_state(0.0, np.zeros(NUM_JOINTS))])
    with pytest.raises(RenderError, match=r'has no /ground_truth_odom; the video needs'):
        states_from_bag(read_bag(bag))


# ---------------------------------------------------------------------------- validation


@pytest.mark.parametrize(('text', 'expected'), [('640x480', (640, 480)), ('64X48', (64, 48))])
def test_parse_size(text: str, expected: tuple[int, int]) -> None:
    assert parse_size(text) == expected


@pytest.mark.parametrize(('text', 'message'), [
    ('640', 'is not WIDTHxHEIGHT'), ('axb', 'is not WIDTHxHEIGHT'),
    ('8x8', 'each side must be 16..4096'), ('640x480x3', 'is not WIDTHxHEIGHT')])
def test_parse_size_errors(text: str, message: str) -> None:
    with pytest.raises(RenderError, match=message):
        parse_size(text)


def test_output_path_errors(tmp_path: Path) -> None:
    with pytest.raises(RenderError, match=r"unknown video format '.avi'; name the file .mp4"):
        check_output_path(tmp_path / 'x.avi', 64, 48, 30)
    with pytest.raises(RenderError, match=r"unknown video format '\(no suffix\)'"):
        check_output_path(tmp_path / 'x', 64, 48, 30)
    with pytest.raises(RenderError, match=r'directory .*/missing does not exist'):
        check_output_path(tmp_path / 'missing' / 'x.mp4', 64, 48, 30)
    with pytest.raises(RenderError, match='needs an even width and height, got 65x48'):
        check_output_path(tmp_path / 'x.mp4', 65, 48, 30)
    with pytest.raises(RenderError, match=r'--fps 0 is out of range'):
        check_output_path(tmp_path / 'x.gif', 65, 48, 0)
    (tmp_path / 'dir.mp4').mkdir()
    with pytest.raises(RenderError, match='is a directory'):
        check_output_path(tmp_path / 'dir.mp4', 64, 48, 30)


def test_unwritable_directory(tmp_path: Path) -> None:
    locked = tmp_path / 'locked'
    locked.mkdir(mode=0o500)
    if os.geteuid() == 0:  # root may write there; procfs refuses writes even to root
        locked = Path('/proc/self')
        assert not os.access(locked, os.W_OK)
    with pytest.raises(RenderError, match=f'^cannot write {locked}/x.mp4: permission denied'):
        check_output_path(locked / 'x.mp4', 64, 48, 30)


# ---------------------------------------------------------------------------- analyze_bag


@pytest.fixture(scope='module')
def fall_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_run_bag(tmp_path_factory.mktemp('video') / 'run.bag', 1.0, with_imu=False,
                         fall_time_s=0.5)


def test_analyze_bag_video(fall_bag: Path, tmp_path: Path,
                           capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / 'run.gif'
    assert analyze_main([str(fall_bag), '--video', str(out), '--fps', '5',
                         '--size', '64x48']) == 0
    assert f'wrote {out} (5 frames at 5 fps)' in capsys.readouterr().err
    with Image.open(out) as gif:
        assert gif.n_frames == 5


def run_script(*args: str) -> subprocess.CompletedProcess[str]:
    env = {key: value for key, value in os.environ.items() if key != 'PYTHONPATH'}
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True,
                          env=env, cwd='/', check=False, timeout=120)


@pytest.mark.parametrize(('args', 'message'), [
    (['--video', 'OUT/run.avi'], "unknown video format '.avi'"),
    (['--video', 'OUT/missing/run.mp4'], 'does not exist'),
])
def test_analyze_bag_video_errors_are_one_line(fall_bag: Path, tmp_path: Path, args: list[str],
                                               message: str) -> None:
    args = [arg.replace('OUT', str(tmp_path)) for arg in args]
    done = run_script(str(fall_bag), *args)
    assert done.returncode == 1
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith('analyze_bag.py: error: ')
    assert message in lines[0]
    assert done.stdout == ''  # checked before the analysis is printed


@pytest.mark.parametrize(('args', 'message'), [
    (['--size', '10'], "argument --size: '10' is not WIDTHxHEIGHT"),
    (['--fps', '0'], "argument --fps: '0' is out of range"),
])
def test_analyze_bag_bad_option_values_are_usage_errors(fall_bag: Path, args: list[str],
                                                        message: str) -> None:
    """Exit 2 and argparse's usage, as for any bad argument."""
    done = run_script(str(fall_bag), '--video', 'run.mp4', *args)
    assert done.returncode == 2
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith('analyze_bag.py: error: ') and message in last
    assert done.stdout == ''
