"""Step as the simulator's behaviour for control mode Step (sim/behaviour.py's protocol).

It stands (the balancing Stand, taken over where the robot stands) until a client desires a
step, takes it quasi-statically (static_step), and stands again where it landed. The
desired step is the latest one sent: a target equal to the one last taken is not taken
again (a client may stream its STEP at 1 kHz), and one sent while a step is under way is
taken after it. Where the target desired as a step touched down differs from that step's,
it is the next one (as BDI's library went on at once, before clients answered the
SWAYING that touchdown reports: the walking tutorial's client, counting its steps on that
SWAYING, already sends the step after it). Each target is clamped from the stance foot
(step_queue's limits) and reported as `desired_step_saturated`.

The step is taken over the world's ground (sim/ground.py's rays, loose bodies where the
simulator has them): its target on the highest ground under the sole's footprint there (a
hollow block's rims, where the ray at its centre falls through a hole), its CoM height the
Stand's over the stance sole's surface less STANCE_DROP_SHARE of that surface's height over
the lowest in play, and its swing over the highest ground under the sole's sweep
(static_step, step_over). On level ground all three are as they were.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import mujoco
import numpy as np

from tutorial_atlas_control.balance import StandBehaviour
from tutorial_atlas_control.sim import Ground
from tutorial_atlas_control.walking.footsteps import Footstep
from tutorial_atlas_control.walking.leg_tasks import foot_pose
from tutorial_atlas_control.walking.static_step import StaticStep, StepGains
from tutorial_atlas_control.walking.status_flags import SWAYING
from tutorial_atlas_control.walking.step_over import sweep_points, terrain_top_m
from tutorial_atlas_control.walking.step_queue import DEFAULT_LIMITS, StepLimits, clamp_step

__all__ = ['StepBehaviour', 'StepStatus']

#: A step's CoM height is the Stand's over the stance sole's surface lowered by this share of
#: that surface's height over the lowest surface in play (the other sole's, the target's): a
#: foot stepping down off a block must reach the floor, a trailing foot on the floor must
#: reach it until it lifts. Neither this share nor 0.6-1 took the second foot from the floor
#: onto a 0.2 m block (docs/vrc.md): from the floor's height the stance knee on the block
#: is on its effort limit, from half-way the trailing leg is straight before the weight is
#: over the block.
STANCE_DROP_SHARE = 0.5
_UP = (0.0, 0.0, 1.0)


@dataclass(frozen=True)
class StepStatus:
    """What step_feedback reports: SWAYING 1 or STEPPING 2, the swing's time left (s), the
    steps taken, the next index wanted, and the step under way or last taken, clamped."""

    status_flags: int
    t_step_rem_s: float
    current_step_index: int
    next_step_index_needed: int
    step_saturated: Footstep | None


class StepBehaviour:
    """Quasi-static steps on `stand`'s balance, one per new desired target."""

    def __init__(self, stand: StandBehaviour, gains: StepGains | None = None,
                 limits: StepLimits = DEFAULT_LIMITS) -> None:
        self.stand = stand
        self.gains = gains
        self.limits = limits
        #: The latest target a client sent (a sole's step), None before any.
        self.desired: Footstep | None = None
        #: The step under way (None while standing).
        self.static_step: StaticStep | None = None
        self.steps_taken = 0
        self._taken: Footstep | None = None
        self._saturated: Footstep | None = None
        #: The target desired when the step under way touched down (None: not yet down).
        self._desired_at_touchdown: Footstep | None = None
        #: The world's ground, its loose bodies where the simulator has them (from start).
        self._ground: Ground | None = None

    def desire(self, step: Footstep | None) -> None:
        """A client's target (None: no step wanted)."""
        self.desired = step

    def start(self, data: mujoco.MjData) -> None:
        """Stand where the robot stands; the count of steps starts again."""
        if self._ground is None:
            self._ground = Ground(self.stand.atlas.model, data)
        self.stand.start(data)
        self.static_step, self.steps_taken = None, 0
        self._taken = self._saturated = self._desired_at_touchdown = None

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        """This tick's f_out (N m, (28,)), within the effort limits."""
        stand = self.stand
        if self.static_step is not None and self.static_step.done:
            self.static_step = None
            self.steps_taken += 1
            stand.start(data)  # stand where it landed
        if self.static_step is None:
            wanted = self._next_target()
            if wanted is not None:
                self._begin(data, wanted)
        static_step = self.static_step
        if static_step is None:
            return stand.torque(data)
        atlas = stand.atlas
        state = stand.estimator.estimate_stepped(data)
        was_down = static_step.landed is not None
        torque = static_step.tick_torque(state, data.qpos[atlas.qpos_adr],
                                      data.qvel[atlas.dof_adr], float(data.time))
        if not was_down and static_step.landed is not None:
            self._desired_at_touchdown = self.desired
        return torque

    def _next_target(self) -> Footstep | None:
        """The step to take now, if any: the one desired at the last touchdown when that
        was new, else the newest one sent when it is not the one last taken."""
        at_touchdown, self._desired_at_touchdown = self._desired_at_touchdown, None
        for wanted in (at_touchdown, self.desired):
            if wanted is not None and not _same_target(wanted, self._taken):
                return wanted
        return None

    def _begin(self, data: mujoco.MjData, wanted: Footstep) -> None:
        stand = self.stand
        assert stand.controller is not None  # started
        stand.start(data)  # the reference from where it stands now
        state = stand.last_state
        assert state is not None and stand.controller is not None  # set by start
        feet = (foot_pose(state, 0), foot_pose(state, 1))
        step = self._on_footprint(clamp_step(wanted, feet[1 - wanted.foot_index], self.limits))
        stance_z, lowest, top = self._terrain(feet, step)
        # The Stand pose's CoM height over the stance sole's surface, less a share of its
        # height over the lowest in play (0 on the plane).
        base = stance_z - STANCE_DROP_SHARE * (stance_z - lowest)
        self.static_step = StaticStep(stand.controller, feet, step, state, float(data.time),
                                      base + stand.com_height_m, self.gains)
        self.static_step.clear_terrain(top)
        self._taken, self._saturated = wanted, step

    def _footprint_top(self, pose: Footstep) -> float:
        """The highest ground (m) under a sole's footprint at `pose` (-inf over none): the
        surface a flat sole lands on (one ray at the sole's centre, over a hollow block
        lying flat, falls through a hole to the floor while the sole lands on the rims)."""
        ground = self._ground
        assert ground is not None  # set by start
        centre = np.array([pose.x_m, pose.y_m])
        return terrain_top_m(sweep_points(centre, centre, pose.yaw_rad, pose.yaw_rad,
                                          self.stand.estimator.sole_half_size_m),
                             ground.height_m)

    def _on_footprint(self, step: Footstep) -> Footstep:
        """`step` on the highest ground under its footprint where the ground is not level
        (as it is, on the level)."""
        assert self._ground is not None  # set by start
        if self._ground.level_m is not None:
            return step
        top = self._footprint_top(step)
        return replace(step, z_m=top) if math.isfinite(top) else step

    def _terrain(self, feet: tuple[Footstep, Footstep], step: Footstep
                 ) -> tuple[float, float, float]:
        """(the ground under the stance sole, the lowest of the ground under the soles and
        the step's surface, the highest ground under the swing sole's sweep to the step)
        (m; a sole's own height where no ground is under it)."""
        ground = self._ground
        assert ground is not None  # set by start
        if ground.level_m is not None:
            return ground.level_m, min(ground.level_m, step.z_m), ground.level_m
        under = [self._footprint_top(foot) for foot in feet]
        under = [h if math.isfinite(h) else foot.z_m for h, foot in zip(under, feet)]
        lowest = min(under + [step.z_m])
        stance_z = under[1 - step.foot_index]
        swing = feet[step.foot_index]
        sweep = sweep_points(np.array([swing.x_m, swing.y_m]), np.array([step.x_m, step.y_m]),
                             swing.yaw_rad, step.yaw_rad, self.stand.estimator.sole_half_size_m)
        return stance_z, lowest, terrain_top_m(sweep, ground.height_m)

    def status(self, time_s: float) -> StepStatus:
        """step_feedback's values now."""
        static_step = self.static_step
        flags = SWAYING if static_step is None else static_step.status
        remaining = 0.0 if static_step is None else static_step.remaining_s(time_s)
        return StepStatus(flags, remaining, self.steps_taken, self.steps_taken + 1,
                          self._saturated)


def _same_target(step: Footstep, other: Footstep | None) -> bool:
    """Whether two desired steps ask for the same pose of the same foot, whatever the
    surface's height and normal under it (the interface casts them again on every STEP,
    and a loose block a foot stands on moves by micrometres: a STEP streamed for the
    target just reached is not a new target)."""
    return other is not None and replace(step, z_m=0.0, normal=_UP) == replace(
        other, z_m=0.0, normal=_UP)
