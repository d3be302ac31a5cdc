"""When the stepping loop sends what it published, and how long it waits for wall time.

Sending is a syscall per topic and subscriber and a wake-up of each subscriber, so the
loop sends in batches whenever being on time allows: at real_time_factor 0 every
FLUSH_PERIOD_S of wall time; paced, after every step while on schedule, and every
CATCH_UP_FLUSH_PERIOD_S while catching up. The clock and the sleep are parameters, so that
tests can drive the decisions with a fake clock.

With DRCSim 2.6's synchronization window on (synchronization.py), the loop also waits before
a step for the controller's command, after sending what is queued: that wait is part of the
step's wall time, so the pacer sleeps only what is left of the step's share, or catches up
(within MAX_LAG_S) when the wait made the loop late. real_time_factor stays a ceiling.

Catching up runs at most CATCH_UP_SPEEDUP times the factor, not flat out: a client that
answers every state stays in the loop. Flat out, a loaded host's 0.85 s stall at 0.25x real
time came back as a burst of 212 steps in a few milliseconds, all on the client's last
command (its arm 0.17 rad off a sine it tracks within 0.08 rad). DRCSim's Gazebo never
caught up: a stall there cost sim time.
"""

from __future__ import annotations

import time
from collections.abc import Callable

from tutorial_atlas_control.units import NS_PER_S

__all__ = ['CATCH_UP_FLUSH_PERIOD_S', 'CATCH_UP_LAG_S', 'CATCH_UP_SPEEDUP', 'FLUSH_PERIOD_S',
           'MAX_LAG_S', 'Pacer']

#: When the loop falls further behind wall time than this, it stops trying to catch up.
#: Below it, the loop runs faster (sending in batches) until it is back on schedule,
#: so a loaded machine's short stalls cost no sim time.
MAX_LAG_S = 1.0
#: Catching up, sim time runs at most this many times real_time_factor: each step keeps
#: half its share of wall time (at 0.25x, 2 ms for a client's answer; at 1x, 0.5 ms).
CATCH_UP_SPEEDUP = 2.0
#: At real_time_factor 0 the loop sends what it published at most this often (s, wall);
#: paced runs send after every step while on schedule. At this period the sends cost a
#: fraction of a physics step, and /clock still advances 250 times a wall second.
FLUSH_PERIOD_S = 0.004
#: A paced run more than CATCH_UP_LAG_S behind wall time sends at most every
#: CATCH_UP_FLUSH_PERIOD_S (s, wall) until it has caught up: on a loaded machine the
#: syscalls of sending every step are what keeps it behind.
CATCH_UP_LAG_S = 0.005
CATCH_UP_FLUSH_PERIOD_S = 0.004


class Pacer:
    """Sim time against wall time: flush decisions and the wait after each step.

    `restart` sets the reference: sim time `sim_ns` is due now; at real_time_factor r,
    sim time sim_ns + d is due d / r later.
    """

    def __init__(self, real_time_factor: float,
                 clock: Callable[[], float] = time.perf_counter,
                 sleep: Callable[[float], None] = time.sleep) -> None:
        self.real_time_factor = real_time_factor
        self.clock = clock
        self.sleep = sleep
        self.wall0_s = clock()
        self.sim0_ns = 0
        self.last_flush_s = self.wall0_s
        #: When the last wait let a step go (clock's s), and the sim time it waited for.
        self.released_s, self.released_sim_ns = self.wall0_s, 0

    def restart(self, sim_ns: int) -> None:
        """Sim time `sim_ns` is due now: after a pause, a rewind, or too large a lag."""
        self.wall0_s, self.sim0_ns = self.clock(), sim_ns
        self.released_s, self.released_sim_ns = self.wall0_s, sim_ns

    def flushed(self) -> None:
        """The loop has just sent everything (outside flush_due)."""
        self.last_flush_s = self.clock()

    def due_s(self, sim_ns: int) -> float:
        """The wall time (clock's seconds) at which sim time `sim_ns` is due (paced only)."""
        return self.wall0_s + (sim_ns - self.sim0_ns) / NS_PER_S / self.real_time_factor

    def flush_due(self, sim_ns: int) -> bool:
        """After a step that ended at `sim_ns`: send now? (True counts as sent.)"""
        if sim_ns < self.sim0_ns:  # reset_simulation rewound time
            self.restart(sim_ns)
        now_s = self.clock()
        if self.real_time_factor > 0.0:
            flush = (now_s - self.due_s(sim_ns) < CATCH_UP_LAG_S
                     or now_s - self.last_flush_s >= CATCH_UP_FLUSH_PERIOD_S)
        else:
            flush = now_s - self.last_flush_s >= FLUSH_PERIOD_S
        if flush:
            self.last_flush_s = now_s
        return flush

    def wait(self, sim_ns: int) -> None:
        """Sleep until sim time `sim_ns` is due, and, when catching up, until its share of
        wall time at CATCH_UP_SPEEDUP times the factor has passed since the last step went;
        give up catching up beyond MAX_LAG_S."""
        if self.real_time_factor <= 0.0:
            return
        now_s = self.clock()
        release_s = self.due_s(sim_ns)
        if release_s - now_s < -MAX_LAG_S:
            self.restart(sim_ns)
            return
        if sim_ns > self.released_sim_ns:
            share_s = ((sim_ns - self.released_sim_ns) / NS_PER_S
                       / (self.real_time_factor * CATCH_UP_SPEEDUP))
            release_s = max(release_s, self.released_s + share_s)
        if release_s > now_s:
            self.sleep(release_s - now_s)
        self.released_s, self.released_sim_ns = max(release_s, now_s), sim_ns
