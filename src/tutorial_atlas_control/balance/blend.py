"""The smoothstep every timed move of the controllers follows, and its rate.

Stand's transitions, StandPrep, Step's sway and the walk's pelvis height and heading all
move a reference from where it is to a goal by s(t / T) = 3 f^2 - 2 f^3: no jump in the
reference nor in its rate at either end, which a step in the rate would put into the
torques. One definition, so that a reference and the rate fed forward with it agree.
"""

from __future__ import annotations

__all__ = ['smoothstep', 'smoothstep_rate']


def smoothstep(fraction: float) -> float:
    """0 at 0 and before, 1 at 1 and beyond, with zero slope at both ends."""
    s = min(max(fraction, 0.0), 1.0)
    return s * s * (3.0 - 2.0 * s)


def smoothstep_rate(fraction: float, duration_s: float) -> float:
    """d/dt of smoothstep(t / duration_s) at `fraction` = t / duration_s (1/s): 0 outside
    0..1, where smoothstep is held."""
    if not 0.0 < fraction < 1.0:
        return 0.0
    return 6.0 * fraction * (1.0 - fraction) / duration_s
