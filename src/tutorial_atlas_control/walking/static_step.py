"""Step: one quasi-static step, on the Stand's whole-body balance.

Three phases: the weight shifted over the stance foot (the capture point's reference,
with the pressure centre on it, moved there by a smoothstep; once the capture point is near
it the other foot, still down, carries nothing: SWAYING), the other foot lifted
and placed along swing.SwingPath with the capture point held over the stance sole
(STEPPING), then the weight brought back between the feet (SWAYING again); `done` once it
is there and at rest. Nothing is dynamic: at any instant the robot could stop and stand.

Where the terrain under the swing's sweep (clear_terrain: the caller's rays) or its end
rises above the lower of its ends (a cinder block stepped onto, across or off), the swing
steps over it instead (step_over.StepOverPath: up, across at the clearance, down; slower,
step_over_swing_s), its servo fed the path's target through LegTasks.foot_servo.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from tutorial_atlas_control.balance import (
    BalanceState,
    StandController,
    dcm_feedback_cop,
    smoothstep,
)
from tutorial_atlas_control.walking.footsteps import Footstep
from tutorial_atlas_control.walking.leg_tasks import LegGains, LegTasks, foot_pose
from tutorial_atlas_control.walking.phases import (
    STATIC_STEP_PHASES,
    PhaseEnd,
    PhaseSequence,
    swing_to,
)
from tutorial_atlas_control.walking.status_flags import STEPPING
from tutorial_atlas_control.walking.step_over import (
    STEP_OVER_CLEARANCE_M,
    StepOverPath,
    clear_apex_m,
    needs_step_over,
)
from tutorial_atlas_control.walking.swing import SwingPath, quintic

__all__ = ['StaticStep', 'StepGains']

_SHIFT, _SWING, _SETTLE = STATIC_STEP_PHASES


@dataclass(frozen=True)
class StepGains:
    """The quasi-static step's numbers (ours)."""

    #: k of p = p_ref + (1 + k)(xi - xi_ref), as Walk's.
    dcm_gain: float = 1.5
    #: How long the weight takes to shift onto the stance foot, and back (s).
    shift_s: float = 1.0
    #: The other foot carries nothing (the Stand's split gives each foot in contact a
    #: share) once the capture point is this near the stance sole's centre (m) ...
    unload_m: float = 0.04
    #: ... and lifts once it is this near (m) ...
    over_stance_m: float = 0.02
    #: ... or this long after the shift began anyway (s).
    longest_shift_s: float = 2.0
    #: The shortest swing (s): a step's duration below it is lengthened.
    shortest_swing_s: float = 0.6
    #: The step is over once the capture point is this near the feet's midpoint (m), or
    #: this long after the weight began to shift back (s).
    at_rest_m: float = 0.01
    longest_settle_s: float = 2.0
    #: How far below the Stand's CoM height the step is taken (m), as Walk's: at the
    #: Stand's height a trailing leg lifts off with its hip pitch, knee and ankle pitch on
    #: their limits and the servo cannot lift it.
    lowering_m: float = 0.05
    #: A swing stepping over higher terrain: how high over it the sole crosses (m), and
    #: the shortest such swing (s; a third up, a third across, a third down).
    step_over_clearance_m: float = STEP_OVER_CLEARANCE_M
    step_over_swing_s: float = 1.5
    legs: LegGains = field(default_factory=LegGains)


class StaticStep:
    """One quasi-static step of `step` (a sole's target, already clamped) from the feet
    where they stand (`feet`: left, right)."""

    def __init__(self, stand: StandController, feet: tuple[Footstep, Footstep],
                 step: Footstep, state: BalanceState, time_s: float, stand_com_height_m: float,
                 gains: StepGains | None = None) -> None:
        self.gains = gains or StepGains()
        self.step = step
        self.feet = list(feet)
        self.legs = LegTasks(stand, self.gains.legs, time_s)
        self.legs.move_height(stand_com_height_m - self.gains.lowering_m, time_s,
                              self.gains.shift_s)
        #: The phase (shift, swing, settle; SWAYING or STEPPING, step_feedback's status) and
        #: when it began.
        self.phases = PhaseSequence(STATIC_STEP_PHASES, time_s,
                                    PhaseEnd(self.gains.shift_s, self.gains.longest_shift_s))
        self.landed: Footstep | None = None
        self.swing_s = max(step.duration_s, self.gains.shortest_swing_s)
        #: The height the swing crosses at when it steps over (None: SwingPath's swing).
        self.apex_m: float | None = None
        stance = self.feet[1 - step.foot_index]
        self._shift = (time_s, state.capture_point.copy(), np.array([stance.x_m, stance.y_m]))
        self._swing: SwingPath | StepOverPath | None = None

    def clear_terrain(self, terrain_top_m: float) -> None:
        """Before the swing: the highest ground under its sweep is `terrain_top_m` (m); where
        it or the step's end rises above the lower end, the swing steps over it."""
        start_z, step = self.feet[self.step.foot_index].z_m, self.step
        if needs_step_over(start_z, step.z_m, terrain_top_m):
            self.apex_m = clear_apex_m(start_z, step.z_m, terrain_top_m,
                                       self.gains.step_over_clearance_m)
            self.swing_s = max(self.swing_s, self.gains.step_over_swing_s)

    @property
    def status(self) -> int:
        """SWAYING or STEPPING, as step_feedback reports it."""
        return self.phases.status

    @property
    def done(self) -> bool:
        """The weight is back between the feet, at rest."""
        return self.phases.done

    def remaining_s(self, time_s: float) -> float:
        """The time left in the swing (s; 0 outside it)."""
        if self.status != STEPPING:
            return 0.0
        return max(0.0, self.swing_s - self.phases.elapsed_s(time_s))

    def _capture_reference(self, time_s: float) -> np.ndarray:
        started_s, start, goal = self._shift
        s = smoothstep((time_s - started_s) / self.gains.shift_s)
        return (1.0 - s) * start + s * goal

    def _condition(self, state: BalanceState) -> bool:
        """What ends the phase under way once its time allows: the capture point over the
        stance sole (shift) or at rest between the feet (settle), the swing foot touching."""
        phase = self.phases.phase
        if phase is _SWING:
            return bool(state.in_contact[self.step.foot_index])
        near_m = self.gains.over_stance_m if phase is _SHIFT else self.gains.at_rest_m
        return float(np.linalg.norm(state.capture_point - self._shift[2])) < near_m

    def _advance(self, state: BalanceState, time_s: float) -> None:
        """Move on to the next phase when this one ends: the swing, then the landing taken
        and the weight shifted back, then done."""
        phases, gains, step = self.phases, self.gains, self.step
        if not phases.ended(time_s, self._condition(state)):
            return
        following = phases.following(more_steps=False)
        if following is _SWING:
            self._swing = swing_to(state, step, self.swing_s)
            if self.apex_m is not None:
                swing = self._swing
                apex = max(self.apex_m, float(swing.start[2]), float(swing.end[2]))
                self._swing = StepOverPath(swing.start, swing.end, swing.start_yaw_rad,
                                           swing.end_yaw_rad, swing.duration_s, apex)
            stance = self.feet[1 - step.foot_index]
            self.legs.face(stance.yaw_rad, step.yaw_rad, time_s, self.swing_s)
            end = PhaseEnd.swing(self.swing_s, gains.legs.late_touchdown_s)
            if isinstance(self._swing, StepOverPath):  # landed once down on its surface
                end = PhaseEnd(self._swing.descent_s, end.longest_s)
            phases.enter(following, time_s, end)
        elif following is _SETTLE:
            self.landed = foot_pose(state, step.foot_index, step.step_index)
            self.feet[step.foot_index] = self.landed
            left, right = self.feet
            middle = np.array([0.5 * (left.x_m + right.x_m), 0.5 * (left.y_m + right.y_m)])
            self._shift = (time_s, state.capture_point.copy(), middle)
            self.legs.face(left.yaw_rad, right.yaw_rad, time_s, gains.shift_s)
            phases.enter(following, time_s, PhaseEnd(gains.shift_s, gains.longest_settle_s))
        else:
            phases.finish()

    def tick_torque(self, state: BalanceState, joint_positions: np.ndarray,
                    joint_velocities: np.ndarray, time_s: float) -> np.ndarray:
        """The 28 joint torques (N m) for this 1 ms tick, within the effort limits."""
        self._advance(state, time_s)
        xi_ref = self._capture_reference(time_s)
        cop = dcm_feedback_cop(state.capture_point, xi_ref, self.gains.dcm_gain)
        swinging = self.status == STEPPING
        unloading = self.landed is None and not swinging and float(
            np.linalg.norm(state.capture_point - self._shift[2])) < self.gains.unload_m
        unloaded = self.step.foot_index if swinging or unloading else None
        legs = self.legs
        torque, _, contact = legs.torque(state, joint_positions, joint_velocities, time_s, cop,
                                         unloaded)
        path = self._swing
        if not swinging:
            return legs.finish(state, joint_velocities, torque, contact, None, self.feet)
        assert path is not None  # set with STEPPING
        elapsed_s = self.phases.elapsed_s(time_s)
        if isinstance(path, SwingPath):
            return legs.finish(state, joint_velocities, torque, contact,
                               (self.step.foot_index, path, elapsed_s), self.feet)
        torque += self._step_over_torque(state, joint_velocities, path, elapsed_s)
        return legs.stand.layer.limit(torque)

    def _step_over_torque(self, state: BalanceState, joint_velocities: np.ndarray,
                          path: StepOverPath, elapsed_s: float) -> np.ndarray:
        """The swing leg's torques along a step-over path, as LegTasks.swing_torque does
        along a SwingPath: its acceleration fed forward, its end pressed into the surface,
        past its end on down at touchdown_speed_m_s."""
        gains = self.gains.legs
        position, velocity, yaw, yaw_rate = path.at(elapsed_s)
        acceleration, yaw_acceleration = path.acceleration(elapsed_s)
        if not gains.swing_feedforward:
            acceleration, yaw_acceleration = None, 0.0
        position[2] -= gains.swing_press_m * quintic(elapsed_s / path.duration_s)[0]
        late = elapsed_s - path.duration_s
        if late > 0.0:  # not down yet: on down
            position[2] -= gains.touchdown_speed_m_s * late
            velocity[2] = -gains.touchdown_speed_m_s
        return self.legs.foot_servo(state, joint_velocities, self.step.foot_index, position,
                                    velocity, yaw, yaw_rate, acceleration, yaw_acceleration,
                                    world=gains.world_velocity)
