"""Walk: dynamic walking over the step queue, on the Stand's whole-body balance.

A walk is a row of phases: a sway (both feet down, the capture point moved over towards
the first stance foot), then one single-support phase per step (the stance foot carries
the whole wrench, the other foot swings to its target along swing.SwingPath), then a
catch (both feet down, the capture point brought to rest between them), after which
Stand takes over. At each touchdown the capture point's plan (dcm_plan) is made again
over the steps the queue then holds, so a streaming client's new steps enter it as
they come.

Each 1 ms step: the pressure centre p = p_ref + (1 + k)(xi - xi_ref) is kept inside the
support polygon (the stance sole alone while a foot swings), the Stand's centroidal
wrench and contact split turn it into torques by inverse statics, and the swing foot's
task-space PD force, mapped through its Jacobian, moves the swing leg; the legs' posture
PD of Stand is off (in single support the stance leg's joints follow from the pelvis
and the foot, the swing leg's from its task).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from tutorial_atlas_control.balance import (
    BalanceState,
    StandController,
    clamp_into,
    convex_hull,
    orientation_error,
    smoothstep,
    yaw_of,
    yaw_rotation,
)
from tutorial_atlas_control.walking.dcm_plan import DcmPlan, tracking_cop
from tutorial_atlas_control.walking.footsteps import Footstep, wrap_angle
from tutorial_atlas_control.walking.step_queue import (
    CATCHING,
    STEPPING,
    SWAYING,
    StepQueue,
)
from tutorial_atlas_control.walking.swing import SwingPath

#: The leg joints (tutorial order): their Stand posture PD is off while walking.
LEG_JOINTS = slice(4, 16)


@dataclass(frozen=True)
class WalkGains:
    """The walk's numbers (ours)."""

    #: k of p = p_ref + (1 + k)(xi - xi_ref): the capture point's error decays at omega k.
    dcm_gain: float = 1.5
    #: How long the first sway and the last catch take (s).
    sway_s: float = 0.6
    catch_s: float = 0.6
    #: The catch ends once the capture point is this near the feet's midpoint (m), or
    #: after longest_catch_s (s).
    at_rest_m: float = 0.01
    longest_catch_s: float = 3.0
    #: The swing foot's task-space PD: position (N/m, N s/m), orientation (N m/rad, N m s/rad).
    #: At 2500 N/m and 200 N m/rad the first swing foot lagged its path by 3 cm and landed
    #: late; these walk DRCSim's queue and 20 straight steps.
    swing_kp: float = 6000.0
    swing_kd: float = 150.0
    swing_rotation_kp: float = 600.0
    swing_rotation_kd: float = 30.0
    #: Damping on the leg joints (N m s/rad) in place of Stand's posture PD.
    leg_kd: float = 2.0
    #: A swing foot not down when its step's time is up keeps going down at this speed
    #: (m/s), for at most late_touchdown_s (s), before the next step begins anyway.
    touchdown_speed_m_s: float = 0.2
    late_touchdown_s: float = 0.4
    #: The yaw moment a stance sole may take, per newton it bears (m): the model's
    #: torsional friction is 0.02 m (sim/atlas_v1.xml); beyond it the foot turns.
    torsion_m: float = 0.015
    #: A foot put back down aims this far below the ground (m), so that it lands.
    press_m: float = 0.005
    #: A sole is flat on the ground with its centre below flat_height_m (m) and its normal
    #: within acos(flat_cos) of vertical (0.05 rad).
    flat_height_m: float = 0.005
    flat_cos: float = 0.99875


@dataclass(frozen=True)
class WalkOutput:
    """One step's decision, for feedback and tests."""

    torque_nm: np.ndarray         # (28,)
    desired_cop: np.ndarray       # (2,)
    capture_point_ref: np.ndarray  # (2,)
    phase: int                    # SWAYING, STEPPING or CATCHING
    swing_foot: int | None


def foot_pose(state: BalanceState, foot: int, step_index: int = 0) -> Footstep:
    """Where a foot is now, as a step (sole centre and heading)."""
    centre = state.sole_centres[foot]
    return Footstep(step_index, foot, float(centre[0]), float(centre[1]),
                    yaw_of(state.sole_rotations[foot]))


def sway_cop(xi_now: np.ndarray, xi_target: np.ndarray, omega: float,
             duration_s: float) -> np.ndarray:
    """The constant pressure centre that takes the capture point from `xi_now` to
    `xi_target` in `duration_s` (xi(T) = p + (xi0 - p) exp(omega T), solved for p)."""
    growth = math.exp(omega * duration_s)
    return (np.asarray(xi_target) - growth * np.asarray(xi_now)) / (1.0 - growth)


class WalkController:
    """Walks the queue's steps from a standing start; `done` once it stands again."""

    def __init__(self, stand: StandController, queue: StepQueue, state: BalanceState,
                 time_s: float, gains: WalkGains | None = None) -> None:
        self.stand = stand
        self.queue = queue
        self.gains = gains or WalkGains()
        self.phase = SWAYING
        self.done = False
        self.phase_start_s = time_s
        #: The step being taken (None while swaying or catching) and its swing path.
        self.step: Footstep | None = None
        self.swing: SwingPath | None = None
        self._plan: DcmPlan | None = None
        #: The Stand's joint PD with the legs' posture gains off (damping leg_kd instead).
        joint_kp, joint_kd = stand.gains.joint_kp.copy(), stand.gains.joint_kd.copy()
        joint_kp[LEG_JOINTS] = 0.0
        joint_kd[LEG_JOINTS] = self.gains.leg_kd
        self._joint_gains = (joint_kp, joint_kd)
        self._sway_cop = np.zeros(2)
        #: The pelvis's heading moving on: (start time, duration, from, turn) (s, rad).
        self._facing = (time_s, 1.0, yaw_of(stand.reference.pelvis_rotation), 0.0)
        self._begin_sway(state, time_s)

    # -- the phases ---------------------------------------------------------------------------

    def _plan_steps(self, preview: list[Footstep], omega: float) -> DcmPlan | None:
        """The capture point's plan over the queue's `preview`, from the feet as they are."""
        if not preview:
            return None
        feet = [self.queue.feet[0], self.queue.feet[1]]
        cops, durations = [], []
        for step in preview:
            stance = feet[1 - step.foot_index]
            cops.append((stance.x_m, stance.y_m))
            durations.append(step.duration_s)
            feet[step.foot_index] = step
        final = 0.5 * np.array([feet[0].x_m + feet[1].x_m, feet[0].y_m + feet[1].y_m])
        return DcmPlan.plan(np.array(cops), np.array(durations), final, omega)

    def _begin_sway(self, state: BalanceState, time_s: float) -> None:
        self.phase, self.phase_start_s = SWAYING, time_s
        self._plan = self._plan_steps(self.queue.preview(), state.omega)
        target = (self._plan.start if self._plan is not None
                  else state.sole_centres[:, :2].mean(axis=0))
        self._sway_cop = sway_cop(state.capture_point, target, state.omega, self.gains.sway_s)
        self._sway_from = state.capture_point.copy()

    def _begin_step(self, state: BalanceState, time_s: float) -> None:
        preview = self.queue.preview()
        self._plan = self._plan_steps(preview, state.omega)
        if self._plan is None:
            self._begin_catch(state, time_s)
            return
        step = preview[0]
        lift = state.sole_centres[step.foot_index]
        self.step = step
        stance = self.queue.feet[1 - step.foot_index]
        self._face(stance.yaw_rad, step.yaw_rad, time_s, step.duration_s)
        self.swing = SwingPath(lift.copy(), np.array([step.x_m, step.y_m, 0.0]),
                               foot_pose(state, step.foot_index).yaw_rad, step.yaw_rad,
                               step.duration_s)
        self.phase, self.phase_start_s = STEPPING, time_s

    def _begin_catch(self, state: BalanceState, time_s: float) -> None:
        self._face(self.queue.feet[0].yaw_rad, self.queue.feet[1].yaw_rad, time_s,
                   self.gains.catch_s)
        self.step, self.swing, self._plan = None, None, None
        self.phase, self.phase_start_s = CATCHING, time_s

    def _face(self, first_yaw_rad: float, second_yaw_rad: float, time_s: float,
              duration_s: float) -> None:
        """Turn the pelvis, upright, to face halfway between two feet's headings over
        `duration_s` (a smoothstep from where its heading is now: a jump in the heading's
        reference at each step kicked the pelvis, which the stance sole's little yaw
        moment could not stop)."""
        now = self._heading(time_s)
        goal = first_yaw_rad + 0.5 * wrap_angle(second_yaw_rad - first_yaw_rad)
        self._facing = (time_s, duration_s, now, wrap_angle(goal - now))

    def _heading(self, time_s: float) -> float:
        """The pelvis heading's reference at `time_s` (rad)."""
        started_s, duration_s, start, turn = self._facing
        return start + smoothstep((time_s - started_s) / duration_s) * turn

    def _advance(self, state: BalanceState, time_s: float) -> None:
        """Move on to the next phase when this one's time is up."""
        elapsed = time_s - self.phase_start_s
        if self.phase == SWAYING and elapsed >= self.gains.sway_s:
            self._begin_step(state, time_s)
        elif self.phase == STEPPING and self.step is not None \
                and elapsed >= self.step.duration_s \
                and (state.in_contact[self.step.foot_index]
                     or elapsed >= self.step.duration_s + self.gains.late_touchdown_s):
            self.queue.touchdown(foot_pose(state, self.step.foot_index, self.step.step_index))
            self._begin_step(state, time_s)
        elif self.phase == CATCHING and elapsed >= self.gains.catch_s and (
                np.linalg.norm(state.capture_point - state.sole_centres[:, :2].mean(axis=0))
                < self.gains.at_rest_m or elapsed >= self.gains.longest_catch_s):
            self.done = True

    # -- the references -----------------------------------------------------------------------

    def _capture_reference(self, state: BalanceState,
                           time_s: float) -> tuple[np.ndarray, np.ndarray]:
        """(xi_ref, p_ref) now."""
        elapsed = time_s - self.phase_start_s
        if self.phase == SWAYING:
            growth = math.exp(state.omega * min(elapsed, self.gains.sway_s))
            xi = self._sway_cop + (self._sway_from - self._sway_cop) * growth
            return xi, self._sway_cop
        if self.phase == STEPPING and self._plan is not None:
            return self._plan.reference(0, elapsed)
        middle = state.sole_centres[:, :2].mean(axis=0)
        return middle, middle

    def _swing_torque(self, state: BalanceState, time_s: float) -> np.ndarray:
        """The swing leg's torques (28,) from its foot's task-space PD."""
        assert self.swing is not None and self.step is not None
        foot = self.step.foot_index
        gains = self.gains
        elapsed = time_s - self.phase_start_s
        position, velocity, yaw, yaw_rate = self.swing.at(elapsed)
        late = elapsed - self.swing.duration_s
        if late > 0.0:  # not down yet: on down
            position[2] -= gains.touchdown_speed_m_s * late
            velocity[2] = -gains.touchdown_speed_m_s
        return self._foot_pd(state, foot, position, velocity, yaw, yaw_rate)

    def _foot_pd(self, state: BalanceState, foot: int, position: np.ndarray,
                 velocity: np.ndarray, yaw: float, yaw_rate: float) -> np.ndarray:
        """The leg's torques (28,) moving a sole towards a pose (task-space PD)."""
        gains = self.gains
        twist = state.sole_velocities[foot]
        force = (gains.swing_kp * (position - state.sole_centres[foot])
                 + gains.swing_kd * (velocity - twist[0:3]))
        moment = (gains.swing_rotation_kp
                  * orientation_error(state.sole_rotations[foot], yaw_rotation(yaw))
                  + gains.swing_rotation_kd * (np.array([0.0, 0.0, yaw_rate]) - twist[3:6]))
        return state.sole_jacobians[foot].T @ np.concatenate([force, moment])

    def _flat_down(self, state: BalanceState, foot: int) -> bool:
        """Whether a sole lies flat on the ground (not up, not on an edge)."""
        return (float(state.sole_centres[foot][2]) < self.gains.flat_height_m
                and float(state.sole_rotations[foot][2, 2]) > self.gains.flat_cos)

    def _put_down_torque(self, state: BalanceState, foot: int) -> np.ndarray:
        """A foot off the ground while both should be down: back onto its last pose."""
        pose = self.queue.feet[foot]
        target = np.array([pose.x_m, pose.y_m, -self.gains.press_m])
        return self._foot_pd(state, foot, target, np.zeros(3), pose.yaw_rad, 0.0)

    # -- one step -----------------------------------------------------------------------------

    def step_torque(self, state: BalanceState, joint_positions: np.ndarray,
                    joint_velocities: np.ndarray, time_s: float) -> WalkOutput:
        """The 28 joint torques (N m) for this 1 ms step, within the effort limits."""
        self._advance(state, time_s)
        stand, gains = self.stand, self.gains
        stand.reference = replace(stand.reference,
                                  pelvis_rotation=yaw_rotation(self._heading(time_s)))
        xi_ref, cop_ref = self._capture_reference(state, time_s)
        cop = tracking_cop(state.capture_point, xi_ref, cop_ref, gains.dcm_gain)
        swinging = self.phase == STEPPING and self.step is not None
        if swinging:
            contact = (self.step.foot_index != 0, self.step.foot_index != 1)  # type: ignore[union-attr]
        else:  # swaying or catching: the feet that are down (both, unless a landing is late)
            contact = state.in_contact if any(state.in_contact) else (True, True)
        corners = np.concatenate([_sole_corners(state, foot, stand.sole_half_size_m)
                                  for foot in (0, 1) if contact[foot]])
        cop = clamp_into(convex_hull(corners), cop, stand.gains.cop_margin_m)
        torque = stand.whole_body(state, cop, contact, joint_positions, joint_velocities,
                                  self._joint_gains, gains.torsion_m if swinging else None
                                  ).torque_nm
        if swinging:
            torque += self._swing_torque(state, time_s)
        else:
            for foot in (0, 1):
                if not contact[foot] or not self._flat_down(state, foot):
                    torque += self._put_down_torque(state, foot)
        np.clip(torque, -stand.effort_limit_nm, stand.effort_limit_nm, out=torque)
        return WalkOutput(torque, cop, xi_ref, self.phase,
                          self.step.foot_index if swinging else None)  # type: ignore[union-attr]


def _sole_corners(state: BalanceState, foot: int,
                  half_size_m: tuple[float, float]) -> np.ndarray:
    """The four corners (4, 2) of a sole's bottom face, world x, y."""
    half_length, half_width = half_size_m
    offsets = np.array([[half_length, half_width], [half_length, -half_width],
                        [-half_length, -half_width], [-half_length, half_width]])
    rotation = state.sole_rotations[foot][0:2, 0:2]
    return state.sole_centres[foot][0:2] + offsets @ rotation.T
