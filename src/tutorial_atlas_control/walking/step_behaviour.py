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
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from tutorial_atlas_control.balance import StandBehaviour
from tutorial_atlas_control.walking.footsteps import Footstep
from tutorial_atlas_control.walking.leg_tasks import foot_pose
from tutorial_atlas_control.walking.static_step import StaticStep, StepGains
from tutorial_atlas_control.walking.status_flags import SWAYING
from tutorial_atlas_control.walking.step_queue import DEFAULT_LIMITS, StepLimits, clamp_step

__all__ = ['StepBehaviour', 'StepStatus']


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

    def desire(self, step: Footstep | None) -> None:
        """A client's target (None: no step wanted)."""
        self.desired = step

    def start(self, data: mujoco.MjData) -> None:
        """Stand where the robot stands; the count of steps starts again."""
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
        state = stand.estimator.estimate(data.qpos, data.qvel)
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
            if wanted is not None and wanted != self._taken:
                return wanted
        return None

    def _begin(self, data: mujoco.MjData, wanted: Footstep) -> None:
        stand = self.stand
        assert stand.controller is not None  # started
        stand.start(data)  # the reference from where it stands now
        state = stand.last_state
        assert state is not None and stand.controller is not None  # set by start
        feet = (foot_pose(state, 0), foot_pose(state, 1))
        step = clamp_step(wanted, feet[1 - wanted.foot_index], self.limits)
        self.static_step = StaticStep(stand.controller, feet, step, state, float(data.time),
                                      stand.ground_under_m(state) + stand.com_height_m,
                                      self.gains)
        self._taken, self._saturated = wanted, step

    def status(self, time_s: float) -> StepStatus:
        """step_feedback's values now."""
        static_step = self.static_step
        flags = SWAYING if static_step is None else static_step.status
        remaining = 0.0 if static_step is None else static_step.remaining_s(time_s)
        return StepStatus(flags, remaining, self.steps_taken, self.steps_taken + 1,
                          self._saturated)
