"""The samples a live plot keeps: a rolling window per field, and the watch on ROS time.

A 1 kHz field over a 10 s window is 10 000 points: they live in numpy arrays that grow by
doubling and drop what slid out of the window when full, so appending costs amortized O(1)
per sample and a frame reads two array views, with no per-point Python objects.
"""

from __future__ import annotations

import numpy as np

__all__ = ['ClockWatch', 'RollingSeries']

#: Initial room of a series (samples): grows by doubling.
INITIAL_CAPACITY = 1024
#: ROS time moving back by more than this (s) is a reset (reset_simulation rewinds sim time
#: to 0; reset_world keeps it). Sim time never moves back otherwise.
BACKWARD_JUMP_S = 1e-6


class RollingSeries:
    """(time s, value) samples of one field, the last `window_s` seconds of them."""

    def __init__(self, window_s: float, capacity: int = INITIAL_CAPACITY) -> None:
        if not window_s > 0.0:
            raise ValueError(f'window must be positive, got {window_s}')
        self.window_s = window_s
        self._times = np.empty(capacity)
        self._values = np.empty(capacity)
        self._start = 0
        self._end = 0

    def __len__(self) -> int:
        return self._end - self._start

    @property
    def times_s(self) -> np.ndarray:
        return self._times[self._start:self._end]

    @property
    def values(self) -> np.ndarray:
        return self._values[self._start:self._end]

    def clear(self) -> None:
        self._start = self._end = 0

    def extend(self, times_s: np.ndarray | list[float], values: np.ndarray | list[float]) -> None:
        """Append samples in time order (they follow the ones already held)."""
        times = np.asarray(times_s, dtype=float)
        count = len(times)
        if count == 0:
            return
        if self._end + count > len(self._times):
            self._make_room(count, float(times[-1]))
        self._times[self._end:self._end + count] = times
        self._values[self._end:self._end + count] = values
        self._end += count

    def trim(self, now_s: float) -> None:
        """Forget the samples older than the window before `now_s` (keeping one just before
        it, so that the line reaches the plot's left edge)."""
        first = int(np.searchsorted(self.times_s, now_s - self.window_s, side='right'))
        self._start += max(0, first - 1)

    def _make_room(self, count: int, newest_s: float) -> None:
        self.trim(newest_s)
        held = len(self)
        capacity = len(self._times)
        if held + count > capacity // 2:  # at least half free after a move: amortized O(1)
            capacity = max(2 * capacity, 2 * (held + count))
        times, values = np.empty(capacity), np.empty(capacity)
        times[:held], values[:held] = self.times_s, self.values
        self._times, self._values = times, values
        self._start, self._end = 0, held


class ClockWatch:
    """ROS time as the plot saw it last: says when it moved back (a reset)."""

    def __init__(self) -> None:
        self.last_s: float | None = None

    def moved_back(self, now_s: float) -> bool:
        """Record `now_s`; True when it is earlier than the last time seen."""
        back = self.last_s is not None and now_s < self.last_s - BACKWARD_JUMP_S
        self.last_s = now_s
        return back
