"""DRCSim 2.6's synchronization window, without ROS.

While the latest AtlasCommand asks for it (desired_controller_period_ms non-zero), the
simulator waits before each step, in wall time, for a command fresh enough: one whose
header stamp is no older than the period at the step's time. A controller that answers
every state in time then controls every step, whatever the load. The waits are bounded by
three budgets (DRCSim's parameters, in seconds of wall time): at most `max_per_step_s` per
step, and at most `max_per_window_s` in each window of `window_size_s`; once a budget is
spent the simulator steps on with the command it has.

"Fresh" is DRCSim's test, `step time - stamp <= period`, at the time the coming step ends
(the time /atlas/controller_statistics measures a command's age at, stepping/inbox.py): with
a period of one step, only a command stamped with the last published state's time will do.

The clock and the wait are parameters, so that tests drive the window with a fake clock.
"""

from __future__ import annotations

import enum
import math
import struct
import time
from collections.abc import Callable
from dataclasses import dataclass

from tutorial_atlas_control.errors import AtlasControlError

__all__ = ['DEFAULT_MAX_PER_STEP_S', 'DEFAULT_MAX_PER_WINDOW_S', 'DEFAULT_WINDOW_SIZE_S',
           'MAX_PER_STEP_PARAM', 'MAX_PER_WINDOW_PARAM', 'NS_PER_MS', 'WINDOW_SIZE_PARAM',
           'DelayBudgets', 'DelayReport', 'SyncConfigError', 'SyncOutcome',
           'SynchronizationWindow', 'is_fresh', 'statistics_bytes']

#: DRCSim's parameter names (read from the global namespace: AtlasPlugin's node handle
#: was the root one) and defaults (s, wall).
WINDOW_SIZE_PARAM = '/atlas/delay_window_size'
MAX_PER_WINDOW_PARAM = '/atlas/delay_max_per_window'
MAX_PER_STEP_PARAM = '/atlas/delay_max_per_step'
DEFAULT_WINDOW_SIZE_S = 5.0
DEFAULT_MAX_PER_WINDOW_S = 0.25
DEFAULT_MAX_PER_STEP_S = 0.025
NS_PER_MS = 1_000_000
#: atlas_msgs/SynchronizationStatistics on the wire: TCPROS length, then three float64.
_STATISTICS = struct.Struct('<I3d')


class SyncConfigError(AtlasControlError):
    """A delay parameter is not usable; the message names it."""


@dataclass(frozen=True)
class DelayBudgets:
    """The three budgets (s, wall), DRCSim's defaults unless set."""

    window_size_s: float = DEFAULT_WINDOW_SIZE_S
    max_per_window_s: float = DEFAULT_MAX_PER_WINDOW_S
    max_per_step_s: float = DEFAULT_MAX_PER_STEP_S

    @classmethod
    def from_params(cls, get: Callable[[str, float], object]) -> DelayBudgets:
        """The budgets from the parameter server (`get(name, default)`).

        Raises:
            SyncConfigError: a value is not a finite number >= 0.
        """
        values = []
        for name, default in ((WINDOW_SIZE_PARAM, DEFAULT_WINDOW_SIZE_S),
                              (MAX_PER_WINDOW_PARAM, DEFAULT_MAX_PER_WINDOW_S),
                              (MAX_PER_STEP_PARAM, DEFAULT_MAX_PER_STEP_S)):
            value = get(name, default)
            if isinstance(value, bool) or not isinstance(value, (int, float)) \
                    or not math.isfinite(value) or value < 0.0:
                raise SyncConfigError(f'parameter {name} is {value!r}; it must be a number of '
                                      f'seconds >= 0 (default {default:g})')
            values.append(float(value))
        return cls(*values)


def is_fresh(step_end_ns: int, stamp_ns: int, period_ms: int) -> bool:
    """DRCSim's test: the command stamped `stamp_ns` is no older than `period_ms` at the
    time `step_end_ns` (ns of sim time) of the coming step. Integer ns: no rounding."""
    return step_end_ns - stamp_ns <= period_ms * NS_PER_MS


class SyncOutcome(enum.Enum):
    """How a step's wait ended."""

    FRESH = 'fresh'  # a command fresh enough (or the window was switched off)
    STEP_BUDGET = 'step budget spent'  # waited delay_max_per_step in vain
    WINDOW_BUDGET = 'window budget spent'  # delay_max_per_window spent in this window


@dataclass(frozen=True)
class DelayReport:
    """One step's wait: atlas_msgs/SynchronizationStatistics' fields (s, wall) and how it
    ended; `timeouts`: waits that ended without a wake-up."""

    delay_in_step_s: float
    delay_in_window_s: float
    delay_window_remain_s: float
    outcome: SyncOutcome
    timeouts: int


def statistics_bytes(report: DelayReport) -> bytes:
    """The report as a TCPROS-framed atlas_msgs/SynchronizationStatistics."""
    return _STATISTICS.pack(_STATISTICS.size - 4, report.delay_in_step_s,
                            report.delay_in_window_s, report.delay_window_remain_s)


class SynchronizationWindow:
    """The budgets' bookkeeping across steps (AtlasPlugin::EnforceSynchronizationDelay).

    Args:
        budgets: the three budgets.
        clock: wall time (s); monotonic.
    """

    def __init__(self, budgets: DelayBudgets,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.budgets = budgets
        self.clock = clock
        self.window_start_s: float | None = None  # the first wait opens a window
        self.delay_in_window_s = 0.0

    def enforce(self, fresh: Callable[[], bool],
                wait: Callable[[float], bool]) -> DelayReport:
        """Before a step: wait until `fresh()` within the budgets.

        Args:
            fresh: takes in the commands received so far; True when the latest is fresh
                enough (or no longer asks for the window).
            wait: blocks for at most the given seconds (wall) or until a command arrives;
                True when woken before the timeout.
        """
        budgets = self.budgets
        now_s = self.clock()
        start_s = self.window_start_s
        if start_s is None or now_s >= start_s + budgets.window_size_s:
            self.window_start_s = start_s = now_s
            self.delay_in_window_s = 0.0
        in_step_s = 0.0
        timeouts = 0
        outcome = SyncOutcome.FRESH
        while True:
            if fresh():
                outcome = SyncOutcome.FRESH
                break
            if self.delay_in_window_s >= budgets.max_per_window_s:
                outcome = SyncOutcome.WINDOW_BUDGET
                break
            if in_step_s >= budgets.max_per_step_s:
                outcome = SyncOutcome.STEP_BUDGET
                break
            timeout_s = min(budgets.max_per_step_s - in_step_s,
                            budgets.max_per_window_s - self.delay_in_window_s)
            before_s = self.clock()
            if not wait(timeout_s):
                timeouts += 1
            waited_s = self.clock() - before_s
            in_step_s += waited_s
            self.delay_in_window_s += waited_s
        return DelayReport(in_step_s, self.delay_in_window_s,
                           start_s + budgets.window_size_s - now_s, outcome, timeouts)
