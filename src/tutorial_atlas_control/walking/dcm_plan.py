"""The capture point's plan over a row of footsteps, the reference walking tracks.

With the pressure centre held at the stance foot's centre p_i during step i (duration T_i),
the capture point moves as xi(t) = p_i + (xi_i,end - p_i) exp(omega (t - T_i)). Ending the
walk with the capture point between the last two feet fixes every step's end point by
backward recursion, xi_i,end = p_(i+1) + (xi_(i+1),end - p_(i+1)) exp(-omega T_(i+1))
(Englsberger, Ott and Albu-Schaeffer 2015, with constant pressure centres). The walk tracks
it with the Stand's law, lipm.dcm_feedback_cop with the plan's pressure centre as p_ref:
p = p_ref + (1 + k) (xi - xi_ref), the error decaying at omega k.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tutorial_atlas_control.balance import capture_point_after
from tutorial_atlas_control.walking.errors import WalkingError


@dataclass(frozen=True)
class DcmPlan:
    """Capture-point reference for steps 0..n-1: step i's pressure centre `cops[i]` (m), its
    duration `durations_s[i]`, and its end point `ends[i]`; after the last, `final` (m)."""

    cops: np.ndarray        # (n, 2)
    durations_s: np.ndarray  # (n,)
    ends: np.ndarray        # (n, 2)
    omega: float

    @classmethod
    def plan(cls, cops: np.ndarray, durations_s: np.ndarray, final: np.ndarray,
             omega: float) -> DcmPlan:
        """The end points by backward recursion from the capture point at rest on `final`."""
        cops = np.asarray(cops, dtype=float).reshape(-1, 2)
        durations = np.asarray(durations_s, dtype=float).reshape(-1)
        if len(cops) != len(durations) or len(cops) == 0:
            raise WalkingError('one duration per pressure centre, at least one step')
        if not np.all(durations > 0.0):
            raise WalkingError('every step duration must be positive')
        ends = np.empty_like(cops)
        after = np.asarray(final, dtype=float)
        for i in range(len(cops) - 1, -1, -1):
            ends[i] = after
            after = capture_point_after(after, cops[i], omega, -float(durations[i]))
        return cls(cops, durations, ends, omega)

    @property
    def start(self) -> np.ndarray:
        """Where the capture point must be as step 0 begins."""
        return capture_point_after(self.ends[0], self.cops[0], self.omega,
                                   -float(self.durations_s[0]))

    def reference(self, step: int, t_s: float) -> tuple[np.ndarray, np.ndarray]:
        """(xi_ref, p_ref) at `t_s` into step `step` (clamped to the step's duration)."""
        duration = float(self.durations_s[step])
        t = min(max(t_s, 0.0), duration)
        cop = self.cops[step]
        # capture_point_after's elementwise arithmetic in plain floats (every 1 ms tick)
        growth = math.exp(self.omega * (t - duration))
        (end_x, end_y), (cop_x, cop_y) = self.ends[step].tolist(), cop.tolist()
        return np.array([cop_x + (end_x - cop_x) * growth,
                         cop_y + (end_y - cop_y) * growth]), cop

