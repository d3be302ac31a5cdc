"""The Stand controller: balance on both feet at DRCSim's Stand pose.

Each 1 ms tick it builds the whole-body layer's tasks and constraints (whole_body.py) from
its reference and solves them into the 28 joint torques:
1. centroidal tasks: the horizontal force of the capture-point law (the centre of pressure
   p = xi + k (xi - xi_ref), kept inside the support polygon, gives F_xy = m omega^2 (c - p)),
   the weight plus a PD on the centre-of-mass height, and a PD moment holding the pelvis
   upright at its reference yaw;
2. a contact constraint per sole: that wrench shared between the feet in contact, each share
   pressing down, its pressure centre on the sole and its force within friction, turned into
   joint torques by inverse statics, tau = bias - J_c^T lambda (gravity and Coriolis of the
   whole body included, so no joint has to sag to hold its weight);
3. a posture task on top: a joint PD to the Stand pose, stiff for the back, neck and arms
   (the balance treats them as a rigid load), light damping only on the legs, whose angles
   follow from where the pelvis is held; and the joint torque limits.
With the capture-point gain at 0 the pressure centre sits on the capture point, which then
stops but never returns: that is the planted defect the tests show falling.

Where the package's library is built, a tick (and whole_body) is one C call
(compiled_whole_body, around the inverse statics' C) equal to the Python here to rounding;
the Python is the reference (WHOLE_BODY_ENV=python, STATICS_ENV=python, the QP solver, or
no library).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from tutorial_atlas_control import native
from tutorial_atlas_control.balance import lipm, support
from tutorial_atlas_control.balance.compiled_whole_body import CompiledWholeBody
from tutorial_atlas_control.balance.estimator import BalanceState
from tutorial_atlas_control.balance.stand_pose import STAND_POSE_RAD
from tutorial_atlas_control.balance.whole_body import (
    INVERSE_STATICS,
    CapturePointTask,
    CentroidalTask,
    ComHeightTask,
    ContactConstraint,
    PelvisOrientationTask,
    PostureTask,
    WholeBodyLayer,
    orientation_error,
)

__all__ = ['STAND_JOINT_KD', 'STAND_JOINT_KP', 'WHOLE_BODY_ENV', 'MovedReference',
           'StandController', 'StandGains', 'StandOutput', 'StandReference',
           'moved_reference', 'orientation_error', 'pelvis_frame', 'pitch_of', 'yaw_of',
           'yaw_rotation']

#: Set to `python` for the whole-body tick in Python even where the compiled library is built.
WHOLE_BODY_ENV = 'TAC_WHOLE_BODY'

#: Joint PD to the Stand pose (N m/rad, N m s/rad), tutorial order. Back, neck and arms:
#: DRCSim's atlas_controller gains (config/atlas_controller.yaml), stable at 1 kHz on the
#: light wrists. Legs: a posture regulator weaker than the tutorial's hold, with nothing on
#: the ankles, whose torque the balance alone decides.
STAND_JOINT_KP: np.ndarray = np.array([
    20.0, 4000.0, 2000.0, 20.0,
    300.0, 300.0, 500.0, 500.0, 0.0, 0.0,
    300.0, 300.0, 500.0, 500.0, 0.0, 0.0,
    2000.0, 1000.0, 200.0, 200.0, 50.0, 100.0,
    2000.0, 1000.0, 200.0, 200.0, 50.0, 100.0])
STAND_JOINT_KD: np.ndarray = np.array([
    0.1, 2.0, 1.0, 1.0,
    3.0, 3.0, 5.0, 5.0, 1.0, 1.0,
    3.0, 3.0, 5.0, 5.0, 1.0, 1.0,
    3.0, 20.0, 3.0, 3.0, 0.1, 0.2,
    3.0, 20.0, 3.0, 3.0, 0.1, 0.2])


@dataclass(frozen=True)
class StandGains:
    """The Stand controller's numbers (ours: BDI never published theirs)."""

    #: k of p = xi + k (xi - xi_ref): the capture point's error decays at omega * k (1/s).
    capture_gain: float = 1.0
    #: How far inside the support polygon the pressure centre is kept (m).
    cop_margin_m: float = 0.015
    #: Centre-of-mass height PD (1/s^2, 1/s): a critically damped 3.2 Hz.
    height_kp: float = 400.0
    height_kd: float = 40.0
    #: Pelvis orientation PD (N m/rad, N m s/rad).
    orientation_kp: float = 3000.0
    orientation_kd: float = 300.0
    #: The soles' friction coefficient the contact wrenches are kept within (the model's
    #: sole and floor friction, sim/atlas_v1.xml); None: not limited.
    friction: float | None = 1.0
    #: The whole-body layer's solver (whole_body.SOLVERS): inverse statics, or the contact
    #: QP (docs/controllers.md, "Solver": what each costs and buys on a slope).
    solver: str = INVERSE_STATICS
    #: Joint PD to the Stand pose (N m/rad, N m s/rad), tutorial order.
    joint_kp: np.ndarray = field(default_factory=STAND_JOINT_KP.copy)
    joint_kd: np.ndarray = field(default_factory=STAND_JOINT_KD.copy)


@dataclass(frozen=True)
class StandReference:
    """Where Stand holds the robot: the capture point, the CoM height, the pelvis frame."""

    capture_point: np.ndarray    # (2,) m, world
    com_height_m: float
    pelvis_rotation: np.ndarray  # (3, 3)
    posture_rad: np.ndarray = field(default_factory=lambda: STAND_POSE_RAD.copy())
    #: How fast a moving reference moves (the PDs' damping is about these, so that a
    #: reference on its way is followed rather than dragged behind): the CoM height's rate
    #: (m/s), the pelvis frame's angular velocity (rad/s, world) and the posture's (rad/s).
    com_height_rate_m_s: float = 0.0
    pelvis_angular_velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    posture_rate_rad_s: np.ndarray = field(default_factory=lambda: np.zeros(28))

    @classmethod
    def from_state(cls, state: BalanceState, posture_rad: np.ndarray = STAND_POSE_RAD,
                   forward_offset_m: float = 0.0) -> StandReference:
        """Hold the robot where it stands: the capture point over the soles' midpoint
        (`forward_offset_m` ahead along the pelvis's heading), the CoM at its height,
        the pelvis upright with its current yaw."""
        heading = state.pelvis_rotation[:, 0].copy()
        heading[2] = 0.0
        heading /= np.linalg.norm(heading)
        upright = yaw_rotation(np.arctan2(heading[1], heading[0]))
        middle = state.sole_centres[:, :2].mean(axis=0) + forward_offset_m * heading[:2]
        return cls(middle, float(state.com[2]), upright, np.array(posture_rad, dtype=float))


def yaw_of(rotation: np.ndarray) -> float:
    """The heading (rad) of a frame's x axis about the world z axis."""
    return float(np.arctan2(rotation[1, 0], rotation[0, 0]))


def yaw_rotation(yaw_rad: float) -> np.ndarray:
    """An upright frame turned by `yaw_rad` about z."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


#: A reference's pelvis heading (rad), CoM height (m) and its rate (m/s) moved on: Walk's
#: and Step's legs move these every tick, the rest of the Stand's reference stays.
MovedReference = tuple[float, float, float]


def moved_reference(reference: StandReference, moved: MovedReference) -> StandReference:
    """`reference` with its pelvis frame turned upright to `moved`'s heading and its CoM
    height and rate replaced (a new reference: the package never writes into one)."""
    yaw_rad, height_m, rate_m_s = moved
    return replace(reference, pelvis_rotation=yaw_rotation(yaw_rad), com_height_m=height_m,
                   com_height_rate_m_s=rate_m_s)


def pitch_of(rotation: np.ndarray) -> float:
    """The pitch (rad, + leaning forward) of a frame's x axis below the horizontal."""
    return float(np.arctan2(-rotation[2, 0], np.hypot(rotation[0, 0], rotation[1, 0])))


def pelvis_frame(yaw_rad: float, pitch_rad: float = 0.0) -> np.ndarray:
    """A frame turned by `yaw_rad` about z, then pitched by `pitch_rad` about its own y.

    yaw_rotation(yaw) @ [[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]] written out in floats (every
    tick of a Stand's take-over; the product's three calls cost twice the arithmetic): each
    entry is one rounded product or a factor, the same bits; the `+ 0.0` gives the entries
    the product sums with a +0 term its sign of zero."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    cp, sp = math.cos(pitch_rad), math.sin(pitch_rad)
    return np.array([[c * cp, -s + 0.0, c * sp + 0.0],
                     [s * cp + 0.0, c, s * sp + 0.0],
                     [-sp + 0.0, 0.0, cp]])


@dataclass(frozen=True)
class StandOutput:
    """One tick's decision, kept for feedback and tests."""

    torque_nm: np.ndarray          # (28,)
    desired_cop: np.ndarray        # (2,) m, after clamping into the support polygon
    force_n: np.ndarray            # (3,) desired total contact force
    moment_nm: np.ndarray          # (3,) desired moment about the CoM
    contact_wrenches: np.ndarray   # (2, 6) per foot, after making them feasible


class StandController:
    """Capture-point balance on both feet. Each tick's torque depends on that tick's state
    alone; the only thing kept is the support region prepared for the estimator's polygon."""

    def __init__(self, mass_kg: float, effort_limit_nm: np.ndarray, reference: StandReference,
                 sole_half_size_m: tuple[float, float], gains: StandGains | None = None,
                 compiled: bool | None = None) -> None:
        """`sole_half_size_m`: (half length, half width) of a sole box (m). `compiled`: the
        tick by one C call when the library is built and inverse statics compiled (None:
        unless WHOLE_BODY_ENV says `python`); False: in Python."""
        self.mass_kg = mass_kg
        self.reference = reference
        self.sole_half_size_m = sole_half_size_m
        self.gains = gains or StandGains()
        self.layer = WholeBodyLayer(mass_kg, effort_limit_nm, self.gains.solver, compiled)
        self._contacts: dict[tuple[bool, float | None], ContactConstraint] = {}
        self._region: tuple[np.ndarray, support.Region] | None = None
        self._joint_gains = (self.gains.joint_kp, self.gains.joint_kd)
        statics = self.layer.statics
        library = None if statics is None else native.chosen_library(WHOLE_BODY_ENV, compiled)
        self._kernel = None if library is None else CompiledWholeBody(
            library, statics, mass_kg, self.gains, self.layer.effort_limit_nm)

    @property
    def compiled(self) -> bool:
        """Whether the tick runs the C call."""
        return self._kernel is not None

    @property
    def compiled_whole_body(self) -> CompiledWholeBody | None:
        """The C call (None: the Python tick), for Walk's legs' own call around it."""
        return self._kernel

    def support_region(self, state: BalanceState) -> support.Region | None:
        """The support polygon shrunk by the margin (None: no polygon to keep to)."""
        polygon = state.support_polygon
        if len(polygon) < 3:
            return None
        if self._region is None or self._region[0] is not polygon:
            # The estimator hands over the same polygon while the feet stay put.
            self._region = (polygon, support.Region(polygon, self.gains.cop_margin_m))
        return self._region[1]

    def desired_cop(self, state: BalanceState) -> np.ndarray:
        """The capture-point law's pressure centre, inside the support polygon."""
        cop = lipm.dcm_feedback_cop(state.capture_point, self.reference.capture_point,
                                    self.gains.capture_gain)
        region = self.support_region(state)
        return cop if region is None else region.clamp(cop)

    def tasks(self, state: BalanceState, cop: np.ndarray,
              reference: StandReference) -> list[CentroidalTask]:
        """The centroidal tasks that hold the robot at `reference` with the pressure centre
        at `cop`: the capture point's force, the height's, the pelvis frame's moment."""
        gains = self.gains
        return [CapturePointTask(cop),
                ComHeightTask(reference.com_height_m, reference.com_height_rate_m_s,
                              gains.height_kp, gains.height_kd),
                PelvisOrientationTask(reference.pelvis_rotation,
                                      reference.pelvis_angular_velocity,
                                      gains.orientation_kp, gains.orientation_kd)]

    def centroidal_wrench(self, state: BalanceState,
                          cop: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(force (3,) N, moment about the CoM (3,) N m) the contacts should exert."""
        return self.layer.centroidal_wrench(state, self.tasks(state, cop, self.reference))

    def tick(self, state: BalanceState, joint_positions: np.ndarray,
             joint_velocities: np.ndarray) -> StandOutput:
        """The 28 joint torques (N m) for this tick, clamped to the effort limits."""
        if self._kernel is not None:
            return StandOutput(*self._kernel.tick(
                state, self.support_region(state), self.contacts_for(state.in_contact, None),
                joint_positions, joint_velocities, self._joint_gains, self.reference))
        output = self.whole_body(state, self.desired_cop(state), state.in_contact,
                                 joint_positions, joint_velocities)
        self.layer.limit(output.torque_nm)
        return output

    def _contact(self, carries: bool, torsion_m: float | None) -> ContactConstraint:
        """A sole's contact constraint (made once for each kind: it is the same each tick)."""
        key = (carries, torsion_m)
        made = self._contacts.get(key)
        if made is None:
            half_length, half_width = self.sole_half_size_m
            made = ContactConstraint(carries, half_length, half_width, torsion_m,
                                     self.gains.friction)
            self._contacts[key] = made
        return made

    def contacts_for(self, contact: tuple[bool, bool],
                     torsion_m: float | None) -> tuple[ContactConstraint, ContactConstraint]:
        """Both soles' contact constraints: which carry, their yaw moment limited by
        `torsion_m` (None: not)."""
        return self._contact(contact[0], torsion_m), self._contact(contact[1], torsion_m)

    def whole_body(self, state: BalanceState, cop: np.ndarray, contact: tuple[bool, bool],
                   joint_positions: np.ndarray, joint_velocities: np.ndarray,
                   joint_gains: tuple[np.ndarray, np.ndarray] | None = None,
                   torsion_m: float | None = None,
                   reference: StandReference | None = None,
                   moved: MovedReference | None = None,
                   contacts: tuple[ContactConstraint, ContactConstraint] | None = None
                   ) -> StandOutput:
        """The whole-body layer's torques for `reference` (else the Stand's own; `moved`:
        its pelvis heading, CoM height and rate replaced) with the
        pressure centre at `cop`, pressed by the soles in `contact` (`torsion_m`: their yaw
        moment limited too), plus the joint PD to the reference's posture (`joint_gains`
        (kp, kd), else the Stand's); not yet clamped to the effort limits (Walk adds its
        swing leg's first). `contacts`: the soles' constraints, if not contacts_for's."""
        reference = reference or self.reference
        contacts = contacts or self.contacts_for(contact, torsion_m)
        if self._kernel is not None:
            return StandOutput(*self._kernel.whole_body(
                state, cop, contacts, joint_positions, joint_velocities,
                joint_gains or self._joint_gains, reference, moved))
        if moved is not None:
            reference = moved_reference(reference, moved)
        joint_kp, joint_kd = joint_gains or self._joint_gains
        posture = PostureTask(reference.posture_rad, reference.posture_rate_rad_s, joint_kp,
                              joint_kd)
        solved = self.layer.solve(state, self.tasks(state, cop, reference), contacts,
                                  (posture,), joint_positions, joint_velocities)
        return StandOutput(solved.torque_nm, cop, solved.force_n, solved.moment_nm,
                           solved.contact_wrenches)
