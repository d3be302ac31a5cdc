"""Command age and its moving-window mean and variance, as DRCSim's controller statistics.

DRCSim's AtlasPlugin published /atlas/controller_statistics (atlas_msgs/ControllerStatistics)
so that a user tuning a controller could see how stale the command the robot obeys is:

    command_age          = sim time of the step - header.stamp of the latest applied command
    command_age_mean     = mean of command_age over the last `window` steps
    command_age_variance = its variance over those steps (n - 1 denominator)
    command_age_window_size = the window (s)

"Sim time of the step" is the time the step ends at, which stamps the joint state it
produces (DRCSim's controller ran at Gazebo's already-advanced sim time): a command
stamped with a joint state's stamp and applied in the next step is one step old. A
command with a zero stamp counts as stamped when it is applied; before any command the
stamp is 0, so the age is the time since sim time 0 (DRCSim's value for its unstamped
initial command).

The window holds the ages of consecutive steps only: the node feeds it while somebody
subscribes (so the statistics cost nothing otherwise), and a step that does not follow the
previous one (a new subscriber, a pause of the feeding, a reset that rewinds time) starts
the window again. Until it is full, mean and variance are over the steps it holds, unlike
DRCSim's, whose zero-filled buffer made the first window's values meaningless. Ages are
summed as integer nanoseconds, so the running sums never drift and the variance is exact
(rounded once to float).

Pure Python: no ROS; the node serializes the values (wire.ControllerStatisticsWire).
"""

from __future__ import annotations

import math

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.units import NS_PER_S

#: Parameter names, as DRCSim read them.
WINDOW_PARAM = 'atlas_controller/statistics_time_window_size'
UPDATE_RATE_PARAM = '/atlas/controller_statistics/update_rate'
#: DRCSim's default window (s).
DEFAULT_WINDOW_S = 1.0
#: The largest window accepted (s): the window keeps one age per step (an hour at 1 kHz is
#: 3.6 million of them); longer is a typo, not a tuning aid.
MAX_WINDOW_S = 3600.0
#: DRCSim clamped the publication rate to this range (Hz).
MIN_UPDATE_RATE_HZ = 1.0
MAX_UPDATE_RATE_HZ = 10000.0


class StatisticsConfigError(AtlasControlError):
    """A controller-statistics parameter is not usable; the message names it."""


def window_steps(window_s: float, dt_s: float) -> int:
    """Steps in a window of `window_s` seconds: at least 2, so the variance is defined.

    Raises:
        StatisticsConfigError: `window_s` is not a number in (0, MAX_WINDOW_S].
    """
    if isinstance(window_s, bool) or not isinstance(window_s, (int, float)) \
            or not math.isfinite(window_s) or not 0.0 < window_s <= MAX_WINDOW_S:
        raise StatisticsConfigError(
            f'parameter {WINDOW_PARAM} is {window_s!r}; it must be a number of seconds in '
            f'(0, {MAX_WINDOW_S:g}] (default {DEFAULT_WINDOW_S:g})')
    return max(2, int(round(window_s / dt_s)))


def update_period_ns(rate_hz: float | None) -> int:
    """Least sim time between two publications (ns); 0 (every step) when no rate is set.

    A set rate is clamped to [MIN_UPDATE_RATE_HZ, MAX_UPDATE_RATE_HZ], as DRCSim did.

    Raises:
        StatisticsConfigError: the rate is set but is not a finite number.
    """
    if rate_hz is None:
        return 0
    if isinstance(rate_hz, bool) or not isinstance(rate_hz, (int, float)) \
            or not math.isfinite(rate_hz):
        raise StatisticsConfigError(
            f'parameter {UPDATE_RATE_PARAM} is {rate_hz!r}; it must be a rate in Hz '
            f'(clamped to {MIN_UPDATE_RATE_HZ:g}..{MAX_UPDATE_RATE_HZ:g}), or unset for every step')
    rate_hz = min(max(float(rate_hz), MIN_UPDATE_RATE_HZ), MAX_UPDATE_RATE_HZ)
    return int(round(NS_PER_S / rate_hz))


class CommandAgeStatistics:
    """The latest command's stamp, and the ages of the last `window_steps` consecutive steps.

    Not thread-safe: the node calls it under its lock.
    """

    def __init__(self, dt_s: float, window_s: float = DEFAULT_WINDOW_S,
                 update_rate_hz: float | None = None) -> None:
        self.step_ns = int(round(dt_s * NS_PER_S))
        self.window_steps = window_steps(window_s, dt_s)
        #: The window actually used (s): a whole number of steps.
        self.window_s = self.window_steps * self.step_ns / NS_PER_S
        self.period_ns = update_period_ns(update_rate_hz)
        #: header.stamp of the latest applied command (ns); 0 before any.
        self.command_stamp_ns = 0
        self.age_ns = 0
        self._ages_ns = [0] * self.window_steps
        self._index = 0
        self._count = 0
        self._sum_ns = 0
        self._sum_sq_ns2 = 0
        self._last_step_ns: int | None = None
        self._last_published_ns: int | None = None

    def command_applied(self, stamp_ns: int, now_ns: int) -> None:
        """A command stamped `stamp_ns` is applied from the step ending at `now_ns` on."""
        self.command_stamp_ns = stamp_ns if stamp_ns != 0 else now_ns

    def forget_command(self) -> None:
        """Back to "no command yet" (after a reset that rewinds sim time)."""
        self.command_stamp_ns = 0

    def clear(self) -> None:
        """Empty the window (the next update starts a new one)."""
        self._count = 0
        self._index = 0
        self._sum_ns = 0
        self._sum_sq_ns2 = 0
        self._last_step_ns = None

    def update(self, now_ns: int) -> None:
        """Add the age at the step ending at `now_ns` to the window."""
        if self._last_step_ns is None or now_ns - self._last_step_ns != self.step_ns:
            self.clear()
        self._last_step_ns = now_ns
        age_ns = now_ns - self.command_stamp_ns
        self.age_ns = age_ns
        ages = self._ages_ns
        index = self._index
        if self._count == self.window_steps:
            old_ns = ages[index]
            self._sum_ns -= old_ns
            self._sum_sq_ns2 -= old_ns * old_ns
        else:
            self._count += 1
        ages[index] = age_ns
        self._sum_ns += age_ns
        self._sum_sq_ns2 += age_ns * age_ns
        index += 1
        self._index = 0 if index == self.window_steps else index

    def publication_due(self, now_ns: int) -> bool:
        """True (and counted as published) when the update period has passed since the last."""
        last_ns = self._last_published_ns
        if last_ns is not None and 0 <= now_ns - last_ns < self.period_ns:
            return False
        self._last_published_ns = now_ns
        return True

    @property
    def samples(self) -> int:
        """Ages in the window now (up to window_steps)."""
        return self._count

    @property
    def age_s(self) -> float:
        return self.age_ns / NS_PER_S

    @property
    def mean_s(self) -> float:
        """Mean age over the window (s); 0 while it is empty."""
        if self._count == 0:
            return 0.0
        return self._sum_ns / (self._count * NS_PER_S)

    @property
    def variance_s2(self) -> float:
        """Sample variance of the age over the window (s^2, n - 1 denominator); 0 below 2 ages."""
        n = self._count
        if n < 2:
            return 0.0
        # n * sum(x^2) - sum(x)^2 = n * (n - 1) * variance, exactly in integers
        return (n * self._sum_sq_ns2 - self._sum_ns * self._sum_ns) / (n * (n - 1) * NS_PER_S ** 2)
