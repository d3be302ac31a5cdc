"""Divergence detected after each step and raised, never published or replayed.

MuJoCo resets the state by itself on NaN/Inf/huge values and only warns: checking its
warning counters and the state's finiteness after every step means no silently reset (or
non-finite) state leaves the simulator.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import mujoco

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.units import NS_PER_S

if TYPE_CHECKING:
    from tutorial_atlas_control.sim.law_kernel import CompiledLaw

#: MuJoCo's warnings for an unstable step (plain ints: indexing MjData's counters with the
#: enums is slower, and this runs every step), each with what it means.
DIVERGENCE_WARNINGS = (
    (int(mujoco.mjtWarning.mjWARN_BADQPOS), 'NaN/Inf/huge joint position'),
    (int(mujoco.mjtWarning.mjWARN_BADQVEL), 'NaN/Inf/huge joint velocity'),
    (int(mujoco.mjtWarning.mjWARN_BADQACC), 'NaN/Inf/huge joint acceleration'),
)

#: DivergenceCheck's finding for a state not finite (after the warnings' 1, 2, 3).
NON_FINITE = len(DIVERGENCE_WARNINGS) + 1


class PhysicsDivergenceError(AtlasControlError):
    """The physics produced NaN/Inf or MuJoCo flagged an unstable step."""


class DivergenceCheck:
    """Raise on an unstable step of one MjData; `state_is_finite` tests its qpos and qvel
    (JointLaw's); with the law's compiled `kernel` the counters and the state are tested in
    its one call (the Python's six numpy reads and two calls were a tenth of the offline
    walk's glue around the physics step)."""

    def __init__(self, data: mujoco.MjData, state_is_finite: Callable[[], bool],
                 kernel: CompiledLaw | None = None) -> None:
        self._warning_counts = data.warning.number  # a view: MuJoCo's counters
        self._state_is_finite = state_is_finite
        #: What finds the first sign of divergence: 0 none, 1 + a DIVERGENCE_WARNINGS index,
        #: or NON_FINITE (the compiled one a C call with no Python frame: a caller that
        #: calls check only when it is not 0 spares a call a step).
        self.unsound: Callable[[], int] = (
            self._python_unsound if kernel is None
            else kernel.unsound_call(self._warning_counts, [w for w, _ in DIVERGENCE_WARNINGS]))

    def _python_unsound(self) -> int:
        counts = self._warning_counts
        for index, (warning, _) in enumerate(DIVERGENCE_WARNINGS):
            if counts[warning] > 0:
                return index + 1
        return 0 if self._state_is_finite() else NON_FINITE

    def check(self, sim_time_ns: int) -> None:
        """After a step: raise if it was unstable.

        Raises:
            PhysicsDivergenceError: MuJoCo warned of an unstable step (its counter is
                cleared), or the state is not finite; the message gives the sim time.
        """
        found = self.unsound()
        if not found:
            return
        if found == NON_FINITE:
            what = 'non-finite state'
        else:
            warning, what = DIVERGENCE_WARNINGS[found - 1]
            self._warning_counts[warning] = 0
        raise PhysicsDivergenceError(f'physics diverged at t={sim_time_ns / NS_PER_S:.3f} s '
                                     f'({what})')
