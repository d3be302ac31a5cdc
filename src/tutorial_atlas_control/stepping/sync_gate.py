"""The loop's side of DRCSim 2.6's synchronization window: before a step, wait within the
budgets for a command fresh enough (synchronization.py holds the budgets' arithmetic).

The wait replaces none of the pacing: at real_time_factor > 0 the time waited is part of
the step's wall time, and the pacer (pacing.py) sleeps only what is left of the step's
share, or catches up when the wait made the loop late.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from tutorial_atlas_control import topics
from tutorial_atlas_control.sim import AtlasSimulator
from tutorial_atlas_control.stepping.inbox import CommandInbox
from tutorial_atlas_control.stepping.outputs import LoopOutputs
from tutorial_atlas_control.stepping.pacing import Pacer
from tutorial_atlas_control.stepping.synchronization import (
    DelayReport,
    SynchronizationWindow,
    SyncOutcome,
    is_fresh,
    statistics_bytes,
)
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['SYNC_WARN_PERIOD_S', 'SyncGate']

#: Steps the synchronization window gave up waiting for are warned about at once, then at
#: most this often (s of sim time), with their count.
SYNC_WARN_PERIOD_S = 5.0


class SyncGate:
    """Waits before a step while the newest AtlasCommand asks for the window."""

    def __init__(self, sim: AtlasSimulator, lock: threading.Lock, inbox: CommandInbox,
                 outputs: LoopOutputs, pacer: Pacer, window: SynchronizationWindow) -> None:
        self.sim = sim
        self.lock = lock
        self.inbox = inbox
        self.outbox = outputs.outbox
        self.log = outputs.log
        self.pacer = pacer
        self.window = window
        self.outlet = outputs.outlets.get(topics.SYNCHRONIZATION_STATISTICS)
        self._latch = outputs.latch_synchronization
        #: Blocks up to the given seconds (wall) for a command; True when woken (tests
        #: replace it to drive the window with a fake clock).
        self.wait_for_command: Callable[[float], bool] = inbox.arrived.wait
        self._warned_ns: int | None = None
        self._gave_up = 0
        self._stopping = False  # shutting down: no more waits

    def wake(self) -> None:
        """End the current wait early (DRCSim's /atlas/debug/sync_delay): it checks the
        commands again."""
        self.inbox.arrived.set()

    def stop_waiting(self) -> None:
        """At shutdown: end the current wait and wait no more (a step's budget may be
        long, and the controller gone)."""
        self._stopping = True
        self.inbox.arrived.set()

    def before_step(self) -> None:
        """Wait, within the budgets, for a command fresh enough; queue
        /atlas/synchronization_statistics."""
        report = self.window.enforce(self._command_fresh, self._wait_sent)
        if report.outcome is not SyncOutcome.FRESH:
            self._warn_gave_up(report)
        outlet = self.outlet
        if outlet is None:
            return
        data = statistics_bytes(report)
        if self.outbox.wanted(outlet):
            self.outbox.add(outlet, data)
        if self._latch is not None:
            self._latch(data[4:])

    def _command_fresh(self) -> bool:
        """Apply what arrived; True when the newest command is fresh enough for the coming
        step, or no longer asks for the window; True at shutdown (wake() ends the wait)."""
        inbox = self.inbox
        inbox.arrived.clear()  # before looking: a later arrival wakes the wait
        if self._stopping:
            return True
        with self.lock:
            inbox.apply_pending()
            period_ms = inbox.period_ms
            return period_ms == 0 or is_fresh(self.sim.sim_time_ns + self.sim.step_ns,
                                              inbox.command_stamp_ns, period_ms)

    def _wait_sent(self, timeout_s: float) -> bool:
        """Send what is queued (the state the controller must answer), then wait."""
        self.outbox.flush()
        self.pacer.flushed()
        return self.wait_for_command(timeout_s)

    def _warn_gave_up(self, report: DelayReport) -> None:
        """A step went on without a fresh command: a line at once, then one per
        SYNC_WARN_PERIOD_S of sim time with the count (DRCSim warned at every one)."""
        self._gave_up += 1
        now_ns = self.sim.sim_time_ns
        last_ns = self._warned_ns
        if last_ns is not None and 0 <= now_ns - last_ns < SYNC_WARN_PERIOD_S * NS_PER_S:
            return
        self._warned_ns = now_ns
        count, self._gave_up = self._gave_up, 0
        self.log.warn(f'synchronization window: no command stamped within '
                      f'{self.inbox.period_ms} ms of t='
                      f'{(now_ns + self.sim.step_ns) / NS_PER_S:.3f} s ({report.outcome.value}, '
                      f'{report.delay_in_window_s:.3f} s waited in this window); stepping on '
                      f'with the latest command ({count} step(s) so since the last such line; '
                      'controller stopped or messages lost?)')
