"""The phases Walk and Step share, and the rules that end them.

Walk (walk.py) sways, steps and catches; Step (static_step.py) shifts its weight over the
stance foot, swings and shifts back. Both are a phase clock moved on by the same rules:
- a timed phase (a sway, a shift, a catch, a settle) ends at its shortest time once the
  robot has settled (its capture point where the phase takes it), or at its longest;
- a swing ends at its duration once the foot touches, or duration + late_touchdown_s
  later whether or not it does (the foot is then put down where it is);
- a swing begins along a SwingPath from where the foot lifts to the step's pose.
Each rule is a pure function of the clock and a few figures, tested without MuJoCo.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tutorial_atlas_control.balance import BalanceState, yaw_of
from tutorial_atlas_control.walking.footsteps import Footstep
from tutorial_atlas_control.walking.swing import SwingPath

__all__ = ['PhaseClock', 'settled', 'swing_to', 'touched_down']


@dataclass
class PhaseClock:
    """The phase under way (a status value, status_flags.py) and when it began (s)."""

    phase: int
    started_s: float

    def enter(self, phase: int, time_s: float) -> None:
        """Begin `phase` at `time_s`."""
        self.phase, self.started_s = phase, time_s

    def elapsed_s(self, time_s: float) -> float:
        """How long the phase has run at `time_s` (s)."""
        return time_s - self.started_s


def settled(elapsed_s: float, shortest_s: float, longest_s: float, at_rest: bool) -> bool:
    """Whether a timed phase ends: past its shortest time and at rest, or past its longest."""
    return elapsed_s >= shortest_s and (at_rest or elapsed_s >= longest_s)


def touched_down(touching: bool, swung_s: float, duration_s: float, late_s: float) -> bool:
    """Whether a swing ends: its duration up and the foot touching, or `late_s` past it."""
    return swung_s >= duration_s and (touching or swung_s >= duration_s + late_s)


def swing_to(state: BalanceState, step: Footstep, duration_s: float) -> SwingPath:
    """The swing of `step`'s foot from where its sole is now to the step's pose (its height
    too: the surface it lands on) in `duration_s`."""
    foot = step.foot_index
    return SwingPath(state.sole_centres[foot].copy(), np.array([step.x_m, step.y_m, step.z_m]),
                     yaw_of(state.sole_rotations[foot]), step.yaw_rad, duration_s)
