"""The cameras' frame rate: set_fps's request checked as DRCSim's plugin did, and the sim
times at which a frame is due.

MultiSenseSL's SetMultiCameraFrameRate clamped a request to [1, 30] Hz at 800 x 800 (its
imager mode 1) with one info line; NaN passed its comparisons and reached the sensor. Here
NaN (or an infinity) is refused with one warning and the rate stays.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from tutorial_atlas_control.stereo.multisense import DEFAULT_FPS

__all__ = ['MAX_FPS', 'MIN_FPS', 'FpsRequest', 'FrameClock', 'fps_request']

MIN_FPS = 1.0
MAX_FPS = DEFAULT_FPS
NS_PER_S = 1_000_000_000


@dataclass(frozen=True)
class FpsRequest:
    """What a set_fps message does: the rate to use (None: keep the current one) and the
    line to log ('' for none); `warning` says whether that line is a warning."""

    fps: float | None
    line: str = ''
    warning: bool = False


def fps_request(value: float) -> FpsRequest:
    """set_fps's value clamped to [MIN_FPS, MAX_FPS]; not finite: refused."""
    if not math.isfinite(value):
        return FpsRequest(None, f'set_fps: {value} is not a frame rate; the cameras keep '
                                'their rate', warning=True)
    if value < MIN_FPS:
        return FpsRequest(MIN_FPS, f'set_fps: {value:g} Hz; the camera rate cannot be below '
                                   f'{MIN_FPS:g} Hz at any resolution: {MIN_FPS:g} Hz')
    if value > MAX_FPS:
        return FpsRequest(MAX_FPS, f'set_fps: {value:g} Hz; the camera rate cannot be above '
                                   f'{MAX_FPS:g} Hz at 800 x 800: {MAX_FPS:g} Hz')
    return FpsRequest(value)


class FrameClock:
    """When a frame is due, in sim time: every 1/fps from the first state offered.

    A state at or after the due time is taken (its own time stamps the frame); the next due
    time is one period later, or the state's time when the renderer fell behind by more
    than a period (frames are skipped, not bunched). Sim time going back (a reset of the
    clock) starts over.
    """

    def __init__(self, fps: float = DEFAULT_FPS) -> None:
        self.period_ns = 0
        self.due_ns: int | None = None
        self.set_fps(fps)

    def set_fps(self, fps: float) -> None:
        self.period_ns = round(NS_PER_S / fps)

    def take(self, stamp_ns: int) -> bool:
        """Whether the state at `stamp_ns` is to be rendered (and if so, it is counted)."""
        due = self.due_ns
        if due is None or stamp_ns < due - self.period_ns:
            self.due_ns = stamp_ns + self.period_ns
            return True
        if stamp_ns < due:
            return False
        self.due_ns = due + self.period_ns
        if self.due_ns <= stamp_ns:
            self.due_ns = stamp_ns + self.period_ns
        return True
