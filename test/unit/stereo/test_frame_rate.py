"""set_fps as DRCSim's plugin clamped it, NaN refused, and the frames due at the rate asked
for from the simulator's 30.3 Hz of states."""

from __future__ import annotations

import math

import pytest

from tutorial_atlas_control.stereo.frame_rate import FrameClock, fps_request
from tutorial_atlas_control.stereo.multisense import intrinsics

STATE_PERIOD_NS = 33_000_000  # the simulator's render_state at 30 Hz: every 33 steps of 1 ms


@pytest.mark.parametrize(('asked', 'used'), [(0.2, 1.0), (-5.0, 1.0), (1.0, 1.0), (12.5, 12.5),
                                             (30.0, 30.0), (60.0, 30.0)])
def test_set_fps_is_clamped_to_one_to_thirty_hz(asked: float, used: float) -> None:
    request = fps_request(asked)
    assert request.fps == used
    assert not request.warning
    assert bool(request.line) == (asked != used)


@pytest.mark.parametrize('asked', [math.nan, math.inf, -math.inf])
def test_set_fps_refuses_what_is_not_a_rate_with_one_warning(asked: float) -> None:
    request = fps_request(asked)
    assert request.fps is None and request.warning
    assert len(request.line.splitlines()) == 1


def frames_in(clock: FrameClock, seconds: float, start_ns: int = 0) -> list[int]:
    stamps = range(start_ns, start_ns + round(seconds * 1e9), STATE_PERIOD_NS)
    return [stamp for stamp in stamps if clock.take(stamp)]


@pytest.mark.parametrize('fps', [30.0, 10.0, 1.0, 7.0])
def test_frames_come_at_the_rate_asked_for(fps: float) -> None:
    frames = frames_in(FrameClock(fps), 20.0)
    assert len(frames) / 20.0 == pytest.approx(fps, rel=0.02)
    gaps = [b - a for a, b in zip(frames, frames[1:], strict=False)]
    assert min(gaps) >= 1e9 / fps - STATE_PERIOD_NS  # never bunched


def test_a_reset_clock_starts_the_frames_over() -> None:
    clock = FrameClock(10.0)
    frames_in(clock, 5.0, start_ns=100_000_000_000)
    assert clock.take(1_000_000_000)  # sim time went back: a frame at once


def test_right_camera_info_carries_the_baseline() -> None:
    left, right = intrinsics('left'), intrinsics('right')
    fx = 400.0 / math.tan(1.3962634 / 2)
    assert left.fx == pytest.approx(fx) and right.k == left.k
    assert left.p[3] == 0.0 and right.p[3] == pytest.approx(-fx * 0.07)
