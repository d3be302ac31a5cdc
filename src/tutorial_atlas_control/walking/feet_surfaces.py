"""The surfaces Walk's feet stand on, and the centre of mass's height over them.

Walk's CoM height reference is a world height: the Stand's over the ground where the walk
began, lowered by the walk. On a slope the ground rises (or falls) under the steps while
that height stays: 20 steps of 0.2 m up 8 degrees put the ground 0.56 m higher, and the
pelvis came below the trial's 0.8 m over it at the second step. Here each foot's surface is
its last step's z (at first the ground under its sole), the support height is their mean,
and the walk's heights move with that mean's rise from where the walk began: at each step
the reference moves to the mean of the stance foot's surface and the step's over the step,
as the centre of mass moves from over one pair of feet to the next. The same blend of the
support height is the pendulum's ground (`support_at`: the balance estimator's omega is the
CoM's height over it). On level ground every step's z is the ground's and nothing moves.
"""

from __future__ import annotations

from tutorial_atlas_control.balance import smoothstep

__all__ = ['FeetSurfaces', 'support_height_m']


def support_height_m(left_m: float, right_m: float) -> float:
    """The height (m) the walk's CoM height is measured from: the mean of the feet's
    surfaces."""
    return 0.5 * (left_m + right_m)


class FeetSurfaces:
    """Each foot's surface height (m, world z; left, right), from `start_m` (the ground
    under each sole as the walk begins) on."""

    def __init__(self, start_m: tuple[float, float]) -> None:
        self.start_m = (float(start_m[0]), float(start_m[1]))
        self.now_m = list(self.start_m)
        start = support_height_m(*self.start_m)
        #: The support height moving on: (start time, duration, from, to) (s, m).
        self._moving = (0.0, 1.0, start, start)

    def support_at(self, time_s: float) -> float:
        """The support height (m) at `time_s`: moving from the last step's start to the mean
        of the feet's surfaces along a smoothstep over the step."""
        started_s, duration_s, start, end = self._moving
        if start == end:
            return end
        return start + smoothstep((time_s - started_s) / duration_s) * (end - start)

    @property
    def rise_m(self) -> float:
        """How far (m) the support height has risen since the walk began (negative: gone
        down)."""
        return support_height_m(*self.now_m) - support_height_m(*self.start_m)

    def step(self, foot: int, z_m: float, time_s: float, duration_s: float) -> bool:
        """`foot` steps onto a surface at `z_m` in a step from `time_s` taking `duration_s`
        (s): whether the support height changes."""
        before = support_height_m(*self.now_m)
        self.now_m[foot] = float(z_m)
        after = support_height_m(*self.now_m)
        if after == before:
            return False
        self._moving = (time_s, duration_s, self.support_at(time_s), after)
        return True

    def over_feet_m(self, height_m: float) -> float:
        """A world height given where the walk began (`height_m`, m) over the feet's
        support now: it moved by the support's rise."""
        return height_m + self.rise_m
