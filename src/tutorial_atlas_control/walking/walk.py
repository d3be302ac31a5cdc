"""Walk: dynamic walking over the step queue, on the Stand's whole-body balance.

A walk is a row of phases: a sway (both feet down, the capture point moved over towards
the first stance foot), then one single-support phase per step (the stance foot carries
the whole wrench, the other foot swings to its target along swing.SwingPath), then a
catch (both feet down, the capture point brought to rest between them), after which
Stand takes over. Each step begins with a weight transfer (phases.WeightTransfer): both
feet carry, the pressure centre moves over to the sole that has just landed in 0.03 s (a
foot servo pressing that sole flat on the surface it landed on: the plane it rests on once
it carries, else its step's), and the other foot lifts once
that sole is flat and carries half the weight, or after at most 0.1 s; the swing then
takes the rest of the step's duration, so the step ends when planned and the capture
point's plan, made at the step's start over the step's whole duration, stays the reference
throughout (the blend's slower pressure centre is an error its feedback takes back). At
each touchdown the capture point's plan (dcm_plan) is made again over the steps the queue
then holds, so a streaming client's new steps enter it as they come.

Each 1 ms tick: the pressure centre p = p_ref + (1 + k)(xi - xi_ref), and leg_tasks
turns it into torques (the Stand's whole-body law on the carrying soles, the swing foot's
joint-space servo, feet put back down). The CoM walks 5 cm lower than it stands, but not
below the Stand pose's height over the ground less that and LOWEST_WALK_MARGIN_M: a Stand
already lowered (its legs not reaching a foot that landed turned) walks at its height; that
height is over the feet's surfaces (feet_surfaces), moving up or down with them step by step
on a slope. While a
foot swings, its landing moves with the capture point's error predicted at touchdown
(step_adjustment): a push that the stance sole cannot take back is caught by where the foot
comes down, within the step limits, and the queue reports the step so moved.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from tutorial_atlas_control.balance import (
    MOVED_IN_CALL,
    BalanceState,
    StandController,
    cop_reaching,
    dcm_feedback_cop,
)
from tutorial_atlas_control.walking.compiled_walk_swing import (
    CompiledWalkSwing,
    walk_swing_kernel,
)
from tutorial_atlas_control.walking.dcm_plan import DcmPlan
from tutorial_atlas_control.walking.feet_surfaces import FeetSurfaces
from tutorial_atlas_control.walking.footsteps import Footstep
from tutorial_atlas_control.walking.leg_tasks import (
    LegGains,
    LegTasks,
    sole_flat,
    standing_pose,
)
from tutorial_atlas_control.walking.phases import (
    WALK_PHASES,
    Phase,
    PhaseEnd,
    PhaseSequence,
    WeightTransfer,
    carried_share,
    swing_to,
)
from tutorial_atlas_control.walking.status_flags import STEPPING
from tutorial_atlas_control.walking.step_adjustment import foothold_shift
from tutorial_atlas_control.walking.step_queue import StepQueue, clamp_pose
from tutorial_atlas_control.walking.swing import SwingPath

_SWAY, _SWING, _CATCH = WALK_PHASES
#: How far (m) below the Stand pose's height less walk_lowering_m a walk may still go: one
#: starting from a Stand lowered more than that walks at the height it starts from. (A Stand
#: 13 cm low over a foot that landed 17 degrees turned, lowered 5 cm more, had its pelvis
#: 0.70 m over the ground at the first swing, and the stance leg gave way.)
LOWEST_WALK_MARGIN_M = 0.02


@dataclass(frozen=True)
class WalkGains:
    """The walk's numbers (ours)."""

    #: k of p = p_ref + (1 + k)(xi - xi_ref): the capture point's error decays at omega k.
    dcm_gain: float = 1.5
    #: How far the CoM is lowered while walking (m): over the sway, back up over the catch.
    #: At the Stand's height the trailing leg of a 0.25 m stride lifts off with its hip
    #: pitch, knee and ankle pitch on their limits, and the servo cannot lift it.
    walk_lowering_m: float = 0.05
    #: How long the first sway and the last catch take (s).
    sway_s: float = 0.6
    catch_s: float = 0.6
    #: The catch ends once the capture point is this near the feet's midpoint (m), or
    #: after longest_catch_s (s).
    at_rest_m: float = 0.01
    longest_catch_s: float = 3.0
    #: Whether the swing foot's landing follows the capture point (step_adjustment), and
    #: the least change (m) that moves its path.
    adjust_steps: bool = True
    adjust_tolerance_m: float = 0.001
    #: The weight transfer at each step's start: the pressure centre over in 0.03 s, the
    #: other foot down at most 0.1 s (and a quarter of the step), until the landed sole is
    #: flat (within 1 degree of its surface) and carries half the weight.
    transfer: WeightTransfer = field(
        default_factory=lambda: WeightTransfer(0.1, 0.5, blend_s=0.03))
    #: The legs' gains and limits (leg_tasks).
    legs: LegGains = field(default_factory=LegGains)


@dataclass(frozen=True)
class WalkOutput:
    """One tick's decision, for feedback and tests."""

    torque_nm: np.ndarray         # (28,)
    desired_cop: np.ndarray       # (2,)
    capture_point_ref: np.ndarray  # (2,)
    phase: int                    # SWAYING, STEPPING or CATCHING
    swing_foot: int | None


_new_object = object.__new__


def _output(torque_nm: np.ndarray, desired_cop: np.ndarray, capture_point_ref: np.ndarray,
            phase: int, swing_foot: int | None) -> WalkOutput:
    """WalkOutput(...) without the frozen dataclass's __init__ (an object.__setattr__ a
    field): every tick's."""
    output = _new_object(WalkOutput)
    output.__dict__.update(torque_nm=torque_nm, desired_cop=desired_cop,
                           capture_point_ref=capture_point_ref, phase=phase,
                           swing_foot=swing_foot)
    return output


def _feet_middle(state: BalanceState) -> np.ndarray:
    """The soles' centres' midpoint (x, y): state.sole_centres[:, :2].mean(axis=0)'s sum and
    division in plain floats (the same bits; numpy's mean is some ten Python calls, every
    tick of the catch)."""
    (left_x, left_y, _), (right_x, right_y, _) = state.sole_centres.tolist()
    return np.array([(left_x + right_x) / 2.0, (left_y + right_y) / 2.0])


def _sway_capture_point(sway_xy: tuple[float, float, float, float], omega: float,
                        t_s: float) -> np.ndarray:
    """capture_point_after(start, cop, omega, t_s) for the sway's start and pressure centre
    (`sway_xy`: x, y each), its elementwise arithmetic in plain floats (the same bits)."""
    growth = math.exp(omega * t_s)
    from_x, from_y, cop_x, cop_y = sway_xy
    return np.array([cop_x + (from_x - cop_x) * growth, cop_y + (from_y - cop_y) * growth])


def _phase_over(phase: Phase, step: Footstep | None, state: BalanceState,
                at_rest_m: float) -> bool:
    """What ends the phase under way once its time allows: nothing for the sway, the swing
    foot (`step`'s) touching, the capture point at rest (within `at_rest_m`) between the feet
    for the catch."""
    if phase is _SWING and step is not None:
        return bool(state.in_contact[step.foot_index])
    if phase is _CATCH:
        middle = _feet_middle(state)
        return float(np.linalg.norm(state.capture_point - middle)) < at_rest_m
    return True


def _walk_height_m(stand_height_m: float, gains: WalkGains,
                   standing_height_m: float | None) -> float:
    """The CoM height the walk walks at (m): walk_lowering_m below the Stand's, unless that
    is more than LOWEST_WALK_MARGIN_M below what the Stand pose stands at here."""
    height = stand_height_m - gains.walk_lowering_m
    if standing_height_m is not None:
        lowest = standing_height_m - gains.walk_lowering_m - LOWEST_WALK_MARGIN_M
        height = max(height, min(stand_height_m, lowest))
    return height


def _plan_steps(feet_now: list[Footstep], preview: list[Footstep],
                omega: float) -> DcmPlan | None:
    """The capture point's plan over the queue's `preview`, from the feet as they are."""
    if not preview:
        return None
    feet = [feet_now[0], feet_now[1]]
    cops, durations = [], []
    for step in preview:
        stance = feet[1 - step.foot_index]
        cops.append((stance.x_m, stance.y_m))
        durations.append(step.duration_s)
        feet[step.foot_index] = step
    final = 0.5 * np.array([feet[0].x_m + feet[1].x_m, feet[0].y_m + feet[1].y_m])
    return DcmPlan.plan(np.array(cops), np.array(durations), final, omega)


class WalkController:
    """Walks the queue's steps from a standing start; `done` once it stands again."""

    def __init__(self, stand: StandController, queue: StepQueue, state: BalanceState,
                 time_s: float, gains: WalkGains | None = None,
                 standing_height_m: float | None = None,
                 surfaces_m: tuple[float, float] = (0.0, 0.0)) -> None:
        """`standing_height_m`: the Stand pose's CoM height (m, world z) over the ground
        here; None: the walk lowers the CoM walk_lowering_m from where it starts.
        `surfaces_m`: the ground's height (m) under each sole here (left, right)."""
        self.stand = stand
        self.queue = queue
        self.gains = gains or WalkGains()
        self.legs = LegTasks(stand, self.gains.legs, time_s)
        #: A tick with the foot in the air as one C call (None: in Python).
        self._kernel = walk_swing_kernel(self.legs, self.gains)
        #: The phase (sway, swing or catch) and when it began.
        self.phases = PhaseSequence(WALK_PHASES, time_s,
                                    PhaseEnd(self.gains.sway_s, self.gains.sway_s))
        #: The step being taken (None while swaying or catching) and its swing path.
        self.step: Footstep | None = None
        self.swing: SwingPath | None = None
        #: The step under way as the queue planned it, before any adjustment.
        self._planned_step: Footstep | None = None
        self._plan: DcmPlan | None = None
        self._sway_cop = np.zeros(2)
        #: When the step's other foot lifted, in the step (s); None while the weight moves.
        self._lift_off_s: float | None = None
        #: The pressure centre kept last tick, and where the step's transfer moves it from.
        self._last_cop = state.sole_centres[:, :2].mean(axis=0)
        self._transfer_from = self._last_cop
        #: The sole that landed last, on its step's surface (None before the first step).
        self._landed: Footstep | None = None
        #: Each foot's surface: the walk's heights follow their mean from where it began.
        self.surfaces = FeetSurfaces(surfaces_m)
        #: The CoM height the walk starts from and returns to (m, where it began).
        self.stand_height_m = stand.reference.com_height_m
        #: The CoM height the walk walks at (m).
        self.walk_height_m = _walk_height_m(self.stand_height_m, self.gains, standing_height_m)
        self._begin_sway(state, time_s)

    @property
    def phase(self) -> int:
        """SWAYING, STEPPING or CATCHING."""
        return self.phases.status

    @property
    def phase_start_s(self) -> float:
        """When the phase began (s)."""
        return self.phases.started_s

    @property
    def done(self) -> bool:
        """The walk has caught itself after its last step."""
        return self.phases.done

    # -- the phases ---------------------------------------------------------------------------

    def _begin_sway(self, state: BalanceState, time_s: float) -> None:
        self.legs.move_height(self.walk_height_m, time_s, self.gains.sway_s)
        self._plan = _plan_steps(self.queue.feet, self.queue.preview(), state.omega)
        target = (self._plan.start if self._plan is not None
                  else state.sole_centres[:, :2].mean(axis=0))
        self._sway_cop = cop_reaching(state.capture_point, target, state.omega,
                                     self.gains.sway_s)
        #: The sway's start and pressure centre as floats (x, y each): every sway tick's.
        self._sway_xy = (*state.capture_point.tolist(), *self._sway_cop.tolist())

    def _begin_step(self, phase: Phase, state: BalanceState, time_s: float) -> None:
        preview = self.queue.preview()
        self._plan = _plan_steps(self.queue.feet, preview, state.omega)
        assert self._plan is not None  # entered with steps to take only
        step = preview[0]
        self.step = self._planned_step = step
        stance = self.queue.feet[1 - step.foot_index]
        self.legs.face(stance.yaw_rad, step.yaw_rad, time_s, step.duration_s)
        if self.surfaces.step(step.foot_index, step.z_m, time_s, step.duration_s):  # the CoM
            self.legs.move_height(self.surfaces.over_feet_m(self.walk_height_m), time_s,
                                  step.duration_s)
        self.swing, self._lift_off_s = None, None  # the swing begins once the weight moved
        self._transfer_from = self._last_cop
        self.phases.enter(phase, time_s,
                          PhaseEnd.swing(step.duration_s, self.gains.legs.late_touchdown_s))

    def _begin_catch(self, phase: Phase, time_s: float) -> None:
        self.legs.face(self.queue.feet[0].yaw_rad, self.queue.feet[1].yaw_rad, time_s,
                       self.gains.catch_s)
        self.legs.move_height(self.surfaces.over_feet_m(self.stand_height_m), time_s,
                              self.gains.catch_s)
        self.step, self.swing, self._plan = None, None, None
        self.phases.enter(phase, time_s, PhaseEnd(self.gains.catch_s, self.gains.longest_catch_s))

    def _advance(self, state: BalanceState, time_s: float) -> None:
        """Move on to the next phase when this one ends: a swing's touchdown taken into the
        queue, then another swing while the queue has steps, else the catch."""
        phases, step = self.phases, self.step
        if not (phases.may_end(time_s) and phases.ended(
                time_s, _phase_over(phases.phase, step, state, self.gains.at_rest_m))):
            return
        if phases.phase is _SWING and step is not None:
            landed = standing_pose(state, step.foot_index, step.normal, step.step_index)
            self.queue.touchdown(landed)
            self._landed = replace(landed, z_m=step.z_m)
        following = phases.following(more_steps=bool(self.queue.preview()))
        if following is None:
            phases.finish()
        elif following is _SWING:
            self._begin_step(following, state, time_s)
        else:
            self._begin_catch(following, time_s)

    @property
    def transferring(self) -> bool:
        """Whether the step under way is still moving its weight, both feet down."""
        return self.phases.phase is _SWING and self._lift_off_s is None

    def _stance_pose(self) -> Footstep:
        """The step's stance sole as the transfer presses it: on the surface it landed on."""
        assert self.step is not None  # while stepping
        stance = 1 - self.step.foot_index
        landed = self._landed
        if landed is not None and landed.foot_index == stance:
            return landed
        return self.queue.feet[stance]

    def _lift_off(self, state: BalanceState, time_s: float) -> None:
        """Lift the step's foot once the transfer's rule says so: its swing begins from where
        the sole is, for the rest of the step's duration."""
        step = self.step
        if not self.transferring or step is None:
            return
        elapsed, stance = self.phases.elapsed_s(time_s), 1 - step.foot_index
        flat = sole_flat(state, stance, self._stance_pose(), self.gains.legs.flat_height_m,
                         self.gains.transfer.level_cos)
        share = carried_share(self._last_cop, state.sole_centres[step.foot_index][0:2],
                              state.sole_centres[stance][0:2])
        if self.gains.transfer.lifts(elapsed, step.duration_s, flat, share):
            self._lift_off_s = elapsed
            self.swing = swing_to(state, step, step.duration_s - elapsed,
                                  self.queue.feet[step.foot_index].normal)

    def _transfer_cop(self, cop: np.ndarray, time_s: float) -> np.ndarray:
        """The pressure centre while the weight moves: from where it was as the step began
        towards the law's `cop`, along the transfer's blend."""
        assert self.step is not None  # while stepping
        blend = self.gains.transfer.blend(self.phases.elapsed_s(time_s), self.step.duration_s)
        return self._transfer_from + blend * (cop - self._transfer_from)

    # -- the references -----------------------------------------------------------------------

    def _capture_reference(self, state: BalanceState,
                           time_s: float) -> tuple[np.ndarray, np.ndarray]:
        """(xi_ref, p_ref) now."""
        elapsed = self.phases.elapsed_s(time_s)
        if self.phases.phase is _SWAY:
            return (_sway_capture_point(self._sway_xy, state.omega,
                                        min(elapsed, self.gains.sway_s)), self._sway_cop)
        if self.phase == STEPPING and self._plan is not None:
            return self._plan.reference(0, elapsed)
        middle = _feet_middle(state)
        return middle, middle

    def _adjust(self, state: BalanceState, xi_ref: np.ndarray, cop_ref: np.ndarray,
                time_s: float) -> None:
        """Move the swing foot's landing by where the capture point will be at touchdown
        (step_adjustment), within the step limits from the stance foot."""
        step, planned, plan, swing = self.step, self._planned_step, self._plan, self.swing
        assert step is not None and planned is not None and plan is not None  # with the step
        stance = 1 - step.foot_index
        # numpy's elementwise differences in plain floats (the same bits): every 1 ms tick
        (capture_x, capture_y), (ref_x, ref_y) = state.capture_point.tolist(), xi_ref.tolist()
        (cop_x, cop_y), (centre_x, centre_y, _) = (cop_ref.tolist(),
                                                   state.sole_centres[stance].tolist())
        (heading_x, _, _), (heading_y, _, _), _ = state.sole_rotations[stance].tolist()
        durations = plan.durations_s
        shift_x, shift_y = foothold_shift(
            (capture_x - ref_x, capture_y - ref_y), (heading_x, heading_y),
            (cop_x - centre_x, cop_y - centre_y), self.legs.sole_reach_m, self.gains.dcm_gain,
            state.omega, step.duration_s - (self.phases.elapsed_s(time_s)),
            float(durations[1]) if len(durations) > 1 else None)
        x, y, _ = clamp_pose(step.foot_index, planned.x_m + shift_x, planned.y_m + shift_y,
                             planned.yaw_rad, self.queue.feet[stance], self.queue.limits)
        if math.hypot(x - step.x_m, y - step.y_m) < self.gains.adjust_tolerance_m:
            return
        self.step = replace(planned, x_m=x, y_m=y)
        if swing is not None:  # else it begins at lift-off, to the step as adjusted
            self.swing = replace(swing, end=np.array([x, y, planned.z_m]))
        self.queue.adjust(self.step)

    # -- one tick -----------------------------------------------------------------------------

    def _compiled_swing(self, kernel: CompiledWalkSwing, state: BalanceState,
                        joint_positions: np.ndarray, joint_velocities: np.ndarray,
                        time_s: float) -> WalkOutput | None:
        """tick_torque's swinging tick as one C call (None: not run, a Python estimate's state)."""
        step, swing, plan, planned = self.step, self.swing, self._plan, self._planned_step
        assert step is not None and swing is not None and plan is not None \
            and planned is not None and self._lift_off_s is not None  # swinging
        elapsed = time_s - self.phases.started_s  # phases.elapsed_s
        if self.legs.load_swing_tick(state, joint_positions, joint_velocities, MOVED_IN_CALL,
                                     (step.foot_index, swing, elapsed - self._lift_off_s),
                                     kernel.rule_in_call) is None:
            return None
        kernel.bind(plan, planned, step, self.queue.feet[1 - step.foot_index], self.queue.limits)
        torque, cop, xi_ref, moved = kernel.tick(elapsed, time_s)
        if moved is not None:  # _adjust's new landing, the call's path already ending there
            self.step = replace(planned, x_m=moved[0], y_m=moved[1])
            self.swing = replace(swing, end=np.array([moved[0], moved[1], planned.z_m]))
            self.queue.adjust(self.step)
        self._last_cop = cop
        return _output(torque, cop, xi_ref, STEPPING, step.foot_index)  # the swing's status

    def tick_torque(self, state: BalanceState, joint_positions: np.ndarray,
                    joint_velocities: np.ndarray, time_s: float) -> WalkOutput:
        """The 28 joint torques (N m) for this 1 ms tick, within the effort limits."""
        self._advance(state, time_s)
        swinging = self.phases.phase is _SWING
        if swinging and self._lift_off_s is None:  # transferring: no call on other ticks
            self._lift_off(state, time_s)
        if swinging and self._lift_off_s is not None and self._kernel is not None:
            output = self._compiled_swing(self._kernel, state, joint_positions,
                                          joint_velocities, time_s)
            if output is not None:
                return output
        xi_ref, cop_ref = self._capture_reference(state, time_s)
        if swinging and self.gains.adjust_steps:  # self.phase == STEPPING: the swing's status
            self._adjust(state, xi_ref, cop_ref, time_s)
        cop = dcm_feedback_cop(state.capture_point, xi_ref, self.gains.dcm_gain, cop_ref)
        transferring = swinging and self._lift_off_s is None  # self.transferring
        feet = self.queue.feet
        if transferring:  # both feet carry, the landed one pressed onto its surface
            cop = self._transfer_cop(cop, time_s)
            feet = list(feet)
            stance = self._stance_pose()
            feet[stance.foot_index] = stance
        step = self.step if swinging and not transferring else None
        swing_foot = None if step is None else step.foot_index
        legs = self.legs
        if step is not None:
            assert self.swing is not None and self._lift_off_s is not None  # at lift-off
            swing = (step.foot_index, self.swing,
                     self.phases.elapsed_s(time_s) - self._lift_off_s)
            torque, cop, _ = legs.swing_tick(state, joint_positions, joint_velocities, time_s,
                                             cop, swing)
        else:
            torque, cop, _ = legs.support_torque(state, joint_positions, joint_velocities,
                                                 time_s, cop, feet)
        self._last_cop = cop
        return _output(torque, cop, xi_ref, self.phases.status, swing_foot)
