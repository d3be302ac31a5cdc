"""Divergence detected after each step and raised, never published or replayed.

MuJoCo resets the state by itself on NaN/Inf/huge values and only warns: checking its
warning counters and the state's finiteness after every step means no silently reset (or
non-finite) state leaves the simulator.
"""

from __future__ import annotations

from collections.abc import Callable

import mujoco

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.units import NS_PER_S

#: MuJoCo's warnings for an unstable step (plain ints: indexing MjData's counters with the
#: enums is slower, and this runs every step), each with what it means.
DIVERGENCE_WARNINGS = (
    (int(mujoco.mjtWarning.mjWARN_BADQPOS), 'NaN/Inf/huge joint position'),
    (int(mujoco.mjtWarning.mjWARN_BADQVEL), 'NaN/Inf/huge joint velocity'),
    (int(mujoco.mjtWarning.mjWARN_BADQACC), 'NaN/Inf/huge joint acceleration'),
)


class PhysicsDivergenceError(AtlasControlError):
    """The physics produced NaN/Inf or MuJoCo flagged an unstable step."""


class DivergenceCheck:
    """Raise on an unstable step of one MjData; `state_is_finite` tests its qpos and qvel
    (JointLaw's, which the compiled kernel answers in one call)."""

    def __init__(self, data: mujoco.MjData, state_is_finite: Callable[[], bool]) -> None:
        self._warning_counts = data.warning.number  # a view: MuJoCo's counters
        self._state_is_finite = state_is_finite

    def check(self, sim_time_ns: int) -> None:
        """After a step: raise if it was unstable.

        Raises:
            PhysicsDivergenceError: MuJoCo warned of an unstable step (its counter is
                cleared), or the state is not finite; the message gives the sim time.
        """
        counts = self._warning_counts
        for warning, what in DIVERGENCE_WARNINGS:
            if counts[warning] > 0:
                counts[warning] = 0
                raise PhysicsDivergenceError(
                    f'physics diverged at t={sim_time_ns / NS_PER_S:.3f} s ({what})')
        if not self._state_is_finite():
            raise PhysicsDivergenceError(
                f'physics diverged at t={sim_time_ns / NS_PER_S:.3f} s (non-finite state)')
