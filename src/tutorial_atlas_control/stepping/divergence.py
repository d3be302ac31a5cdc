"""What the loop does when the physics diverges: reset the robot and go on, unless the
model keeps diverging (then it stops, and the node exits with status 1)."""

from __future__ import annotations

from collections.abc import Callable

from tutorial_atlas_control.sim import AtlasSimulator, PhysicsDivergenceError
from tutorial_atlas_control.stepping.outputs import LoopLog
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['DIVERGENCE_REPEAT_S', 'MAX_DIVERGENCES_IN_A_ROW', 'DivergenceGuard',
           'DivergenceRecovery']

#: A divergence this soon (s of sim time) after the previous one's reset is "in a row";
#: that many in a row means the model itself is unstable and the loop stops.
DIVERGENCE_REPEAT_S = 1.0
MAX_DIVERGENCES_IN_A_ROW = 3


class DivergenceGuard:
    """Retry after a divergence (reset the robot), unless the model keeps diverging.

    A divergence within DIVERGENCE_REPEAT_S of sim time after the previous one is "in a
    row"; the MAX_DIVERGENCES_IN_A_ROW-th in a row stops the loop.
    """

    def __init__(self) -> None:
        self.in_a_row = 0
        self.last_ns: int | None = None

    def retry(self, now_ns: int) -> bool:
        """A divergence at sim time `now_ns`: True to reset and go on, False to stop."""
        last_ns = self.last_ns
        if last_ns is not None and 0 <= now_ns - last_ns <= DIVERGENCE_REPEAT_S * NS_PER_S:
            self.in_a_row += 1
        else:
            self.in_a_row = 1
        self.last_ns = now_ns
        return self.in_a_row < MAX_DIVERGENCES_IN_A_ROW


class DivergenceRecovery:
    """Logs a divergence and resets the robot through `reset` (SimControls'), or gives up."""

    def __init__(self, sim: AtlasSimulator, log: LoopLog, reset: Callable[[], None]) -> None:
        self.sim = sim
        self.log = log
        self.reset = reset
        self.guard = DivergenceGuard()

    def recover(self, err: PhysicsDivergenceError) -> bool:
        """After `err` (under the loop's lock): True when the robot was reset and the loop
        goes on, False (stop) when the model keeps diverging."""
        if not self.guard.retry(self.sim.sim_time_ns):
            self.log.fatal(f'{err}: {MAX_DIVERGENCES_IN_A_ROW} times in a row, each within '
                           f'{DIVERGENCE_REPEAT_S} s of the reset; the model '
                           f'{self.sim.atlas_path} is unstable; stopping the simulator')
            return False
        self.log.error(f'{err}; resetting the robot to its initial state')
        self.reset()
        return True
