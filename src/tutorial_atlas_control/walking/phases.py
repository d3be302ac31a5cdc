"""The one phase machine Walk and Step run: their phases in order, each with its end rule,
and the transition from one to the next.

Walk (walk.py) sways, swings once a step and catches; Step (static_step.py) shifts its
weight over the stance foot, swings and settles back. Both are a PhaseSequence:
- every phase ends by one rule (PhaseEnd): past its shortest time once its condition holds,
  or at its longest whether or not. A timed phase (sway, shift, catch, settle) waits for the
  robot at rest (its capture point where the phase takes it); a swing for its foot touching,
  from its duration on, and is over late_touchdown_s later whether or not the foot is down
  (it is then put down where it is);
- the transition: a repeating phase (Walk's swing) is entered again while there are steps
  to take, else the next phase in order (a repeating one skipped when there is nothing for
  it), and none after the last: the sequence is done;
- a walking step begins with a weight transfer (WeightTransfer): both feet carry while the
  pressure centre moves over to the sole that has just landed, until that sole is flat down
  and carries a share of the weight, or its longest time; only then does the other foot lift;
- a swing begins along a SwingPath from where the foot lifts to the step's pose.
Each rule is a pure function of the time and what the behaviour observes, tested without
MuJoCo.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tutorial_atlas_control.balance import BalanceState, smoothstep, yaw_of
from tutorial_atlas_control.walking.footsteps import Footstep
from tutorial_atlas_control.walking.status_flags import CATCHING, STEPPING, SWAYING
from tutorial_atlas_control.walking.swing import SwingPath, surface_tilt, swing_height_m

__all__ = ['STATIC_STEP_PHASES', 'WALK_PHASES', 'Phase', 'PhaseEnd', 'PhaseSequence',
           'WeightTransfer', 'carried_share', 'settled', 'swing_to']


def settled(elapsed_s: float, shortest_s: float, longest_s: float, at_rest: bool) -> bool:
    """Whether a phase ends: past its shortest time and its condition holding (at rest, the
    foot touching), or past its longest."""
    return elapsed_s >= shortest_s and (at_rest or elapsed_s >= longest_s)


@dataclass(frozen=True)
class Phase:
    """A phase: its name, the status value it reports (status_flags.py), and whether it is
    entered again while there are steps to take (Walk's swing, once a step)."""

    name: str
    status: int
    repeats: bool = False


@dataclass(frozen=True)
class PhaseEnd:
    """When a phase ends (settled): past `shortest_s` once its condition holds, or at
    `longest_s` whether or not."""

    shortest_s: float
    longest_s: float

    @classmethod
    def swing(cls, duration_s: float, late_s: float) -> PhaseEnd:
        """A swing's: at its duration once the foot touches, `late_s` past it anyway."""
        return cls(duration_s, duration_s + late_s)

    def ends(self, elapsed_s: float, condition: bool) -> bool:
        return settled(elapsed_s, self.shortest_s, self.longest_s, condition)


@dataclass(frozen=True)
class WeightTransfer:
    """The start of a walking step, both feet down: the pressure centre moves from where it
    was to where the step's law asks (`blend`, a smoothstep over `blend_s`), the landed
    sole pressed flat; the other foot lifts (`lifts`) once the landed sole is flat down and
    carries `share` of the weight, or at the longest time, which is at most `most_of_step`
    of the step's duration (the swing takes the rest: the step still ends on time).
    Without it a landing sole touching by its heel's edge took the whole weight in 4 ms and
    its toes slammed down. The blend is short: the capture point is ahead of the landed
    foot at touchdown, and every millisecond the pressure centre stays back on the other
    sole moves it further (a 0.1 s blend: 3 cm, and the stance foot rolled).

    Flat here is stricter than for a sole put down (LegGains.flat_cos, 2.9 degrees): the
    landed sole within acos(`level_cos`) of its surface. A sole still rolling onto the
    ground passes 2.9 degrees on its way: at the VRC course's mud leg's end a left sole
    whose heel grazed the ground rising ahead (4.6 degrees) counted as flat 17 ms after
    touchdown, rolling onto its toes; the other foot lifted, the weight came onto the toes,
    the heel rose to 44 degrees and the robot fell. Within 1 degree the other foot lifts
    about 24 ms after a touchdown on flat ground rather than 18."""

    longest_s: float
    share: float
    blend_s: float
    most_of_step: float = 0.25
    #: The cosine of how far (1 degree) the landed sole may lie off its surface for the
    #: other foot to lift before the longest time.
    level_cos: float = math.cos(math.radians(1.0))

    def longest_for(self, step_s: float) -> float:
        """The transfer's longest time in a step of `step_s` (s)."""
        return min(self.longest_s, self.most_of_step * step_s)

    def blend(self, elapsed_s: float, step_s: float) -> float:
        """How far (0 to 1) the pressure centre has moved to the law's at `elapsed_s`."""
        longest = min(self.blend_s, self.longest_for(step_s))
        return 1.0 if longest <= 0.0 else smoothstep(elapsed_s / longest)

    def lifts(self, elapsed_s: float, step_s: float, landed_flat: bool,
              landed_share: float) -> bool:
        """Whether the other foot lifts at `elapsed_s` into a step of `step_s`."""
        return (elapsed_s >= self.longest_for(step_s)
                or (landed_flat and landed_share >= self.share))


def carried_share(cop: np.ndarray, lifting_xy: np.ndarray, landed_xy: np.ndarray) -> float:
    """The landed sole's share (0 to 1) of the weight with the pressure centre at `cop`
    between the soles' centres (its place along the line from the lifting one to the landed
    one: the whole-body layer's split between two soles)."""
    span = np.asarray(landed_xy, dtype=float) - np.asarray(lifting_xy, dtype=float)
    length2 = float(span @ span)
    if length2 <= 0.0:
        return 1.0
    along = float((np.asarray(cop, dtype=float) - lifting_xy) @ span) / length2
    return min(max(along, 0.0), 1.0)


#: Walk's phases: the sway over to the first stance foot, a swing per step, the catch.
WALK_PHASES = (Phase('sway', SWAYING), Phase('swing', STEPPING, repeats=True),
               Phase('catch', CATCHING))
#: Step's: the weight shifted over the stance foot, the swing, the weight shifted back.
STATIC_STEP_PHASES = (Phase('shift', SWAYING), Phase('swing', STEPPING),
                      Phase('settle', SWAYING))


class PhaseSequence:
    """`phases` in order, the first entered at `time_s` with its end rule `end`. Each tick
    the behaviour asks `ended` (given what it observes) and, when the phase has, enters
    `following()`'s phase with that phase's rule, or finishes."""

    def __init__(self, phases: Sequence[Phase], time_s: float, end: PhaseEnd) -> None:
        self.phases = tuple(phases)
        self.phase = self.phases[0]
        self.started_s = time_s
        self.end = end
        #: The last phase has ended.
        self.done = False

    @property
    def status(self) -> int:
        """The phase's status value, as feedback reports it."""
        return self.phase.status

    def enter(self, phase: Phase, time_s: float, end: PhaseEnd) -> None:
        """Begin `phase` at `time_s`, ending by `end`."""
        self.phase, self.started_s, self.end = phase, time_s, end

    def elapsed_s(self, time_s: float) -> float:
        """How long the phase has run at `time_s` (s)."""
        return time_s - self.started_s

    def may_end(self, time_s: float) -> bool:
        """Whether the phase under way can end at `time_s` whatever its condition: past its
        shortest time (settled's first test), not done. Most ticks are not: their condition
        need not be observed."""
        return not self.done and time_s - self.started_s >= self.end.shortest_s

    def ended(self, time_s: float, condition: bool) -> bool:
        """Whether the phase under way ends at `time_s` with its condition as observed
        (never once done)."""
        return not self.done and self.end.ends(self.elapsed_s(time_s), condition)

    def following(self, more_steps: bool) -> Phase | None:
        """The phase after the one under way: a repeating one again while there are
        `more_steps`, else the next in order (a repeating one only with steps to take);
        None after the last."""
        if self.phase.repeats and more_steps:
            return self.phase
        for phase in self.phases[self.phases.index(self.phase) + 1:]:
            if more_steps or not phase.repeats:
                return phase
        return None

    def finish(self) -> None:
        """The last phase has ended: `ended` is never true again."""
        self.done = True


def swing_to(state: BalanceState, step: Footstep, duration_s: float,
             start_normal: tuple[float, float, float] = (0.0, 0.0, 1.0)) -> SwingPath:
    """The swing of `step`'s foot from where its sole is now (on a surface of
    `start_normal`) to the step's pose (its height and normal too: the surface it lands
    on) in `duration_s`, its apex clear of the higher end."""
    foot = step.foot_index
    start = state.sole_centres[foot].copy()
    return SwingPath(start, np.array([step.x_m, step.y_m, step.z_m]),
                     yaw_of(state.sole_rotations[foot]), step.yaw_rad, duration_s,
                     swing_height_m(float(start[2]), step.z_m), surface_tilt(start_normal),
                     surface_tilt(step.normal))
