"""The whole-body layer: tasks and constraints over one robot state, turned into joint torques.

Tasks say what the robot should do. A centroidal task asks the contacts for a part of the
wrench about the centre of mass: CapturePointTask the horizontal force that puts the pressure
centre where asked (m omega^2 (c - p)), ComHeightTask the weight and a PD on the centre of
mass's height, PelvisOrientationTask a PD moment holding the pelvis's frame. A joint task adds
torques of its own: PostureTask a joint PD to a posture (the user's joints under k_effort are
the simulator's blend, outside); a behaviour's own (Walk's swing-foot servo) is any callable
giving (28,) torques. Constraints say what cannot be: a ContactConstraint per sole (no pull,
the pressure centre inside the sole, the yaw moment and the tangential force within what
friction holds) and the joint torque limits.

Two solvers, chosen by name (SOLVERS). INVERSE_STATICS, the default: the tasks' wrench,
shared between the soles in contact (contact_wrench.split_wrench), each share made
feasible, becomes tau = bias - J_c^T lambda (gravity and Coriolis of the whole body
included), plus the joint tasks, within the limits. It holds a flat stance exactly and
costs a few microseconds. QP (contact_qp): the soles' wrenches that make the tasks' wrench
as nearly as each sole's friction pyramid and pressure centre about the ground's normal
(MuJoCo's contacts) and the joints' torque limits allow, near the same split: where the
split is feasible, the same wrenches; where not, the other sole carries what one cannot,
for a solve each tick (the figures on a slope: docs/controllers.md, "Solver"). Inverse
statics runs as one C call (compiled_statics) where the package's library is built, equal to
the Python here to rounding; in Python (STATICS_ENV=python, or no library) it computes in
plain floats in numpy's order of operations, Stand's torques the same bits as before the
layer. The tasks are made anew each tick: plain slotted classes,
cheap to make.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from tutorial_atlas_control import native
from tutorial_atlas_control.balance import contact_wrench, lipm
from tutorial_atlas_control.balance.compiled_statics import CompiledStatics
from tutorial_atlas_control.balance.errors import BalanceError
from tutorial_atlas_control.balance.estimator import BalanceState

__all__ = ['INVERSE_STATICS', 'QP', 'SOLVERS', 'CapturePointTask', 'CentroidalTask',
           'ComHeightTask', 'ContactConstraint', 'JointTask', 'PelvisOrientationTask',
           'PostureTask', 'WholeBodyLayer', 'WholeBodyOutput', 'ground_normal',
           'orientation_error']

#: The whole-body layer's solvers: the contact wrenches shared by a rule and clamped, or
#: found by a QP (contact_qp).
INVERSE_STATICS = 'inverse_statics'
QP = 'qp'
SOLVERS = (INVERSE_STATICS, QP)
#: Set to `python` for inverse statics in Python even where the compiled library is built.
STATICS_ENV = 'TAC_STATICS'

#: A joint task: the robot's state, the joints' positions and velocities -> (28,) torques.
JointTask = Callable[[BalanceState, np.ndarray, np.ndarray], np.ndarray]


class CentroidalTask(Protocol):
    """A part of the wrench about the centre of mass the contacts are asked for."""

    def wrench(self, state: BalanceState, mass_kg: float) -> tuple[Sequence[float],
                                                                    Sequence[float]]:
        """(force (3,) N, moment (3,) N m) in the world frame."""


def orientation_error(rotation: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """The small rotation (rad, world axis) that takes `rotation` to `reference`."""
    (d00, d01, d02), (d10, d11, d12), (d20, d21, d22) = (reference @ rotation.T).tolist()
    return np.array([0.5 * (d21 - d12), 0.5 * (d02 - d20), 0.5 * (d10 - d01)])


@dataclass(slots=True)
class CapturePointTask:
    """The horizontal force that makes the pressure centre `cop` ((2,) m, world): the
    linear inverted pendulum's m omega^2 (c - p) (lipm.com_acceleration)."""

    cop: np.ndarray

    def wrench(self, state: BalanceState, mass_kg: float) -> tuple[Sequence[float],
                                                                    Sequence[float]]:
        com_x, com_y, _ = state.com.tolist()
        cop_x, cop_y = np.asarray(self.cop, dtype=np.float64).tolist()
        stiffness = state.omega * state.omega
        return ((mass_kg * (stiffness * (com_x - cop_x) + 0.0),
                 mass_kg * (stiffness * (com_y - cop_y) + 0.0), 0.0), (0.0, 0.0, 0.0))


@dataclass(slots=True)
class ComHeightTask:
    """The weight, and a PD (1/s^2, 1/s) on the centre of mass's height towards `height_m`
    moving at `rate_m_s` (m, m/s): the vertical force."""

    height_m: float
    rate_m_s: float
    kp: float
    kd: float

    def wrench(self, state: BalanceState, mass_kg: float) -> tuple[Sequence[float],
                                                                    Sequence[float]]:
        vertical = (self.kp * (self.height_m - float(state.com[2]))
                    + self.kd * (self.rate_m_s - float(state.com_velocity[2])))
        return (0.0, 0.0, mass_kg * (vertical + lipm.GRAVITY_M_S2)), (0.0, 0.0, 0.0)


@dataclass(slots=True)
class PelvisOrientationTask:
    """A PD moment (N m/rad, N m s/rad) holding the pelvis's frame at `rotation` ((3, 3))
    turning at `angular_velocity` ((3,) rad/s, world)."""

    rotation: np.ndarray
    angular_velocity: np.ndarray
    kp: float
    kd: float

    def wrench(self, state: BalanceState, mass_kg: float) -> tuple[Sequence[float],
                                                                    Sequence[float]]:
        error = orientation_error(state.pelvis_rotation, self.rotation).tolist()
        kp, kd = self.kp, self.kd
        return (0.0, 0.0, 0.0), tuple(kp * e + kd * (w_ref - w) for e, w_ref, w in zip(
            error, self.angular_velocity.tolist(), state.pelvis_angular_velocity.tolist()))


@dataclass(slots=True)
class PostureTask:
    """A joint PD (N m/rad, N m s/rad, (28,) each) to `posture_rad` moving at `rate_rad_s`."""

    posture_rad: np.ndarray
    rate_rad_s: np.ndarray
    kp: np.ndarray
    kd: np.ndarray

    def __call__(self, state: BalanceState, joint_positions: np.ndarray,
                 joint_velocities: np.ndarray) -> np.ndarray:
        return (self.kp * (self.posture_rad - joint_positions)
                + self.kd * (self.rate_rad_s - joint_velocities))


@dataclass(frozen=True)
class ContactConstraint:
    """What one sole's contact wrench may be: none if it does not carry (`carries` False);
    else no pull, the pressure centre inside the sole's half sizes (m), with `torsion_m` the
    yaw moment within torsion_m f_n, and with `friction` the tangential force within
    friction f_n (a cone about the sole's normal). `centre_m`: the centre (along, across;
    sole frame, m) of the rectangle of those half sizes the pressure centre stays in: the
    sole's own (0, 0), or the part of it bearing on the ground (walking/sole_support.py)."""

    carries: bool
    half_length_m: float
    half_width_m: float
    torsion_m: float | None = None
    friction: float | None = None
    centre_m: tuple[float, float] = (0.0, 0.0)

    def feasible(self, wrench: np.ndarray, sole_rotation: np.ndarray) -> np.ndarray:
        """`wrench` [f, m] (world, at the sole's centre) made feasible."""
        return contact_wrench.make_feasible(wrench, sole_rotation, self.half_length_m,
                                            self.half_width_m, self.torsion_m, self.friction,
                                            self.centre_m)


@dataclass(slots=True)
class WholeBodyOutput:
    """One tick's decision, kept for feedback and tests."""

    torque_nm: np.ndarray          # (28,)
    force_n: np.ndarray            # (3,) the centroidal tasks' force
    moment_nm: np.ndarray          # (3,) their moment about the centre of mass
    contact_wrenches: np.ndarray   # (2, 6) per sole, feasible


def ground_normal(state: BalanceState, foot: int) -> np.ndarray:
    """The unit normal of the ground under a sole: the mean of its contacts' normals
    (MuJoCo's), else the sole's own z axis."""
    contacts = state.sole_contacts[foot]
    if not contacts.touching:
        return state.sole_rotations[foot][:, 2].copy()
    normal = contacts.normals.mean(axis=0)
    return normal / np.linalg.norm(normal)


class WholeBodyLayer:
    """Tasks and constraints over one BalanceState, turned into the 28 joint torques by
    `solver` (one of SOLVERS)."""

    def __init__(self, mass_kg: float, effort_limit_nm: np.ndarray,
                 solver: str = INVERSE_STATICS, compiled: bool | None = None) -> None:
        """`compiled`: inverse statics by one C call when the library is built (None: unless
        STATICS_ENV says `python`); False: in Python."""
        if solver not in SOLVERS:
            raise BalanceError(f'whole-body solver {solver!r} is not one of {SOLVERS}')
        self.mass_kg = mass_kg
        self.effort_limit_nm = np.asarray(effort_limit_nm, dtype=float)
        self._lowest_nm = -self.effort_limit_nm
        self.solver = solver
        #: How many ticks the QP found no feasible wrench (inverse statics' was used).
        self.qp_fallbacks = 0
        library = (native.chosen_library(STATICS_ENV, compiled) if solver == INVERSE_STATICS
                   else None)
        self._statics = (None if library is None
                         else CompiledStatics(library, len(self.effort_limit_nm)))

    @property
    def compiled(self) -> bool:
        """Whether inverse statics runs the C call."""
        return self._statics is not None

    @property
    def statics(self) -> CompiledStatics | None:
        """The compiled inverse statics (None: in Python), for a tick around it in C."""
        return self._statics

    def centroidal_wrench(self, state: BalanceState,
                          tasks: Sequence[CentroidalTask]) -> tuple[np.ndarray, np.ndarray]:
        """The tasks' (force (3,), moment (3,)) summed."""
        fx = fy = fz = mx = my = mz = 0.0
        for task in tasks:
            (tfx, tfy, tfz), (tmx, tmy, tmz) = task.wrench(state, self.mass_kg)
            fx, fy, fz, mx, my, mz = fx + tfx, fy + tfy, fz + tfz, mx + tmx, my + tmy, mz + tmz
        return np.array([fx, fy, fz]), np.array([mx, my, mz])

    def solve(self, state: BalanceState, tasks: Sequence[CentroidalTask],
              contacts: tuple[ContactConstraint, ContactConstraint],
              joint_tasks: Sequence[JointTask], joint_positions: np.ndarray,
              joint_velocities: np.ndarray) -> WholeBodyOutput:
        """The torques that make the carrying soles press the tasks' wrench (shared between
        them, each share made feasible), plus the joint tasks; not yet within the effort
        limits (`limit` does that: a behaviour may add a swing leg's torque first)."""
        force, moment = self.centroidal_wrench(state, tasks)
        if self._statics is not None:
            wrenches, torque = self._statics.solve(force, moment, state, contacts)
            for joint_task in joint_tasks:
                torque += joint_task(state, joint_positions, joint_velocities)
            return WholeBodyOutput(torque, force, moment, wrenches)
        carrying = (contacts[0].carries, contacts[1].carries)
        wrenches = contact_wrench.split_wrench(force, moment, state.sole_centres, state.com,
                                               carrying)
        if self.solver == QP and (carrying[0] or carrying[1]):
            base = state.bias_nm.copy()
            for joint_task in joint_tasks:
                base += joint_task(state, joint_positions, joint_velocities)
            solved = self._solve_qp(state, force, moment, wrenches, contacts, base)
            if solved is not None:
                torque = base - state.sole_jacobians.reshape(12, -1).T @ solved.reshape(12)
                return WholeBodyOutput(torque, force, moment, solved)
            self.qp_fallbacks += 1
        for foot in (0, 1):
            wrenches[foot] = contacts[foot].feasible(wrenches[foot], state.sole_rotations[foot])
        torque = state.bias_nm - state.sole_jacobians.reshape(12, -1).T @ wrenches.reshape(12)
        for joint_task in joint_tasks:
            torque += joint_task(state, joint_positions, joint_velocities)
        return WholeBodyOutput(torque, force, moment, wrenches)

    def _solve_qp(self, state: BalanceState, force: np.ndarray, moment: np.ndarray,
                  split: np.ndarray, contacts: tuple[ContactConstraint, ContactConstraint],
                  base_torque_nm: np.ndarray) -> np.ndarray | None:
        """The contact QP's wrenches (contact_qp), each carrying sole's constraint about
        the ground's normal; None when it has none."""
        from tutorial_atlas_control.balance import contact_qp  # noqa: PLC0415 - scipy, on use
        frames = [contact_qp.contact_frame(ground_normal(state, foot),
                                           state.sole_rotations[foot])
                  if contacts[foot].carries else None for foot in (0, 1)]
        sole = contacts[0] if contacts[0].carries else contacts[1]
        return contact_qp.solve_contact_qp(
            np.concatenate([force, moment]), split, state.com, state.sole_centres, frames,
            (sole.half_length_m, sole.half_width_m, sole.torsion_m, sole.friction),
            state.sole_jacobians, base_torque_nm, self.effort_limit_nm)

    def limit(self, torque: np.ndarray) -> np.ndarray:
        """`torque` within the joints' effort limits, in place (np.clip's own arithmetic,
        max then min, without its three Python wrappers: twice a walking tick)."""
        np.maximum(torque, self._lowest_nm, out=torque)
        return np.minimum(torque, self.effort_limit_nm, out=torque)
