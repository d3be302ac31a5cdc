"""DRCSim's MudPlugin as a law: the viscous drag a link feels while it touches the mud.

Gazebo's MudPlugin joined a touching link to the static mud at the mean contact point with a
joint of stiffness 0 and damping c: ODE's soft constraint (erp = 0, cfm = 1/c) on all six
degrees of freedom. That joint's wrench on the link is −c times the link's velocity at the
point (N·s/m) and −c times its angular velocity (N·m·s/rad), no spring, gone when contact
ends. A simulator applies it at the link's centre of mass, where the force stays and its
moment about the centre of mass adds to the torque.

ODE solved that joint with the step, against the velocity at the step's end. Applied as an
explicit force, the drag overshoots where c·dt exceeds twice a degree of freedom's
inertia: Atlas's foot turning about its ankle (about 0.01 kg·m²) at c = 40 and dt = 1 ms
diverges within 10 ms. `implicit_drag` gives the joint's wrench the way ODE solved it,
−c · (I + c·dt·A)⁻¹ · twist, with A the links' mobility at their points (J M⁻¹ Jᵀ): the
drag against the velocity it leaves at the step's end, which is −c · twist as c·dt·A → 0.
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from tutorial_atlas_control.course.errors import CourseError
from tutorial_atlas_control.course.vrc_task_2 import MUD_DAMPING

__all__ = ['MAX_MUD_DAMPING', 'check_mud_damping', 'drag_at_point', 'drag_wrench',
           'implicit_drag', 'wrench_at_com']

#: A damping past this (N·s/m) is refused as absurd: 1000 times the VRC's.
MAX_MUD_DAMPING = 1000.0 * MUD_DAMPING
#: The cross product as a tensor: (a × b)_i = eps_ijk a_j b_k.
_LEVI_CIVITA = np.zeros((3, 3, 3))
for _i, _j, _k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
    _LEVI_CIVITA[_i, _j, _k], _LEVI_CIVITA[_i, _k, _j] = 1.0, -1.0


def check_mud_damping(value: object, what: str = 'mud damping') -> float:
    """`value` as the mud's damping (N·s/m and N·m·s/rad): a finite number, 0 or more.

    Raises:
        CourseError: not a number, not finite, negative or absurd (one line naming `what`).
    """
    number: float | None = None
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        number = float(value)
    if number is None or not math.isfinite(number) or number < 0.0:
        raise CourseError(f'{what} must be a finite number >= 0 (N s/m), got {value!r}')
    if number > MAX_MUD_DAMPING:
        raise CourseError(f'{what} {number:g} N s/m exceeds {MAX_MUD_DAMPING:g}')
    return number


def drag_at_point(damping: float, twist: np.ndarray) -> np.ndarray:
    """The mud's wrench at the contact point, explicit: −c·(v, ω) (N, N·m) for a twist
    (v at the point (m/s), ω (rad/s)) of shape (6,) or (k, 6)."""
    return -damping * np.asarray(twist, dtype=float)


def wrench_at_com(wrench_at_point: np.ndarray, points: np.ndarray,
                  coms: np.ndarray) -> np.ndarray:
    """Wrenches (k, 6) at points (k, 3) moved to the links' centres of mass (k, 3): the
    force unchanged, the torque plus (point − com) × force (world frame)."""
    out = np.array(wrench_at_point, dtype=float).reshape(-1, 6)
    arm = (np.asarray(points, dtype=float) - np.asarray(coms, dtype=float)).reshape(-1, 3)
    out[:, 3:6] += np.einsum('ijk,nj,nk->ni', _LEVI_CIVITA, arm, out[:, 0:3])
    return out


def drag_wrench(damping: float, velocity_at_point: np.ndarray, angular_velocity: np.ndarray,
                point: np.ndarray, com: np.ndarray) -> np.ndarray:
    """DRCSim's drag on one link as the world wrench (6,) at its centre of mass, for
    xfrc_applied: force −c·v (v the link's velocity at the mean contact point), torque
    −c·ω + (point − com) × force."""
    twist = np.concatenate((np.asarray(velocity_at_point, dtype=float),
                            np.asarray(angular_velocity, dtype=float)))
    return wrench_at_com(drag_at_point(damping, twist), point, com)[0]


def implicit_drag(damping: float, dt_s: float, twists: np.ndarray,
                  mobility: np.ndarray) -> np.ndarray:
    """The drag wrenches at the points (k, 6) as ODE's soft joints gave them over a step of
    `dt_s`: −c·(I + c·dt·A)⁻¹·twists, for the stacked twists (k, 6) of the touching links
    and their mobility A (6k, 6k) = J M⁻¹ Jᵀ at the points (rows v then ω, link by link).
    Each wrench is −c times the twist the drag alone leaves at the step's end."""
    stacked = np.asarray(twists, dtype=float).reshape(-1)
    system = (damping * dt_s) * np.asarray(mobility, dtype=float)
    system.flat[::len(stacked) + 1] += 1.0
    # Symmetric positive definite (A is): MuJoCo's Cholesky, 4 times cheaper than numpy's
    # general solve at this size.
    if mujoco.mju_cholFactor(system, 0.0) < len(stacked):
        raise CourseError('the mud links\' mobility is not a positive semi-definite matrix')
    solved = np.empty_like(stacked)
    mujoco.mju_cholSolve(solved, system, stacked)
    return (-damping * solved).reshape(-1, 6)
