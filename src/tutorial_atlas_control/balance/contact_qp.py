"""The contact wrenches by a quadratic programme: the whole-body layer's other solver.

Inverse statics (contact_wrench) shares the tasks' wrench between the soles by a rule and
then clamps each share on its own: a share clamped at its sole's edge or at friction loses
that part of the wrench, which the other sole could have carried. The QP instead finds the
soles' wrenches x = [f_L, m_L, f_R, m_R] (world, at the sole centres) that

    minimise   |A x - w|_W^2 + |x - x0|_S^2
    subject to, for each carrying sole (in its contact frame: the ground's normal n, from
               MuJoCo's contacts, and the sole's x and y laid on that ground):
                 n.f >= 0, |t_i.f| <= mu/sqrt(2) n.f (the friction cone's inscribed pyramid),
                 |t_1.m| <= half_width n.f, |t_2.m| <= half_length n.f (the pressure
                 centre on the sole), |n.m| <= torsion n.f (when asked);
               the joint torques bias + joint tasks - J_c^T x within the effort limits,

where A x is the wrench x makes about the centre of mass, w the tasks' and x0 inverse
statics' split before clamping. Where that split is feasible it is the optimum (both terms
0): the QP then gives inverse statics' wrenches. Elsewhere the tasks' force comes first
(W: a moment weighs as a force at MOMENT_ARM_M, 10 m: the capture point's force is what
keeps the robot up), then their moment, and the split only breaks ties (S:
SPLIT_FORCE_WEIGHT, SPLIT_MOMENT_WEIGHT, a thousandth and a hundredth of W's): what one
sole cannot carry, the other does. Its habit: where the tasks' moment is far out of reach
(a push down a slope asks 230 N m of pitch of soles that make 76), it moves both pressure
centres to opposite corners of their soles, whose few milliradians of toe-out then win a
fraction of a newton metre of pitch (docs/controllers.md, "Solver"). Solved by qpsolvers
with daqp (a dual active-set solver: 12 variables, about 40 inequalities); a programme the
solver finds infeasible falls back to inverse statics' clamped shares.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

import numpy as np
import qpsolvers

__all__ = ['MOMENT_ARM_M', 'QP_SOLVER', 'SPLIT_FORCE_WEIGHT', 'SPLIT_MOMENT_WEIGHT',
           'contact_frame', 'solve_contact_qp']

#: The solver qpsolvers calls.
QP_SOLVER = 'daqp'
#: A moment of 1 N m weighs as much as a force of 1 N at this lever arm (m).
MOMENT_ARM_M = 10.0
#: The weights of staying near inverse statics' split: its forces (per N^2) and its moments
#: (per (N m)^2), against the tasks' force (1 per N^2) and moment (1e-2 per (N m)^2).
SPLIT_FORCE_WEIGHT = 1e-3
SPLIT_MOMENT_WEIGHT = 1e-4


def contact_frame(normal: np.ndarray, sole_rotation: np.ndarray) -> np.ndarray:
    """(3, 3) rows t_1, t_2, n: the sole's x axis laid on the ground of unit `normal`, then
    n x t_1, then n (in plain floats: this runs every tick)."""
    nx, ny, nz = np.asarray(normal, dtype=float).tolist()
    x0, x1, x2 = sole_rotation[:, 0].tolist()
    along = x0 * nx + x1 * ny + x2 * nz
    a, b, c = x0 - along * nx, x1 - along * ny, x2 - along * nz
    size = math.sqrt(a * a + b * b + c * c)
    a, b, c = a / size, b / size, c / size
    return np.array([[a, b, c], [ny * c - nz * b, nz * a - nx * c, nx * b - ny * a],
                     [nx, ny, nz]])


def _wrench_map(lever: np.ndarray) -> np.ndarray:
    """(6, 6): a sole's [f, m] at `lever` (m, from the centre of mass) to the wrench it
    makes about the centre of mass, [f, m + lever x f]."""
    x, y, z = lever.tolist()
    return np.array([[1.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
                     [0.0, 0.0, 1.0, 0.0, 0.0, 0.0], [0.0, -z, y, 1.0, 0.0, 0.0],
                     [z, 0.0, -x, 0.0, 1.0, 0.0], [-y, x, 0.0, 0.0, 0.0, 1.0]])


#: The task's weights, force then moment (MOMENT_ARM_M), and the split's for one and for
#: two soles, as vectors and diagonal matrices.
_WEIGHT = np.array([1.0, 1.0, 1.0] + [1.0 / MOMENT_ARM_M ** 2] * 3)
_SPLIT = np.array([SPLIT_FORCE_WEIGHT] * 3 + [SPLIT_MOMENT_WEIGHT] * 3)
_REGULAR = {count: np.tile(_SPLIT, count) for count in (1, 2)}
_REGULAR_DIAGONAL = {count: np.diag(vector) for count, vector in _REGULAR.items()}


@functools.lru_cache(maxsize=8)
def _sole_coefficients(half_length_m: float, half_width_m: float, torsion_m: float | None,
                       friction: float | None) -> tuple[np.ndarray, np.ndarray]:
    """(C, D) (k, 3) each: one sole's constraint rows are [C F, D F] <= 0, F the contact
    frame (contact_frame): no pull; friction's pyramid (when given); the pressure centre
    on the sole; torsion (when given)."""
    force = [(0.0, 0.0, -1.0)]
    moment = [(0.0, 0.0, 0.0)]
    if friction is not None:
        mu = friction / math.sqrt(2.0)
        for axis in (0, 1):
            for sign in (1.0, -1.0):
                force.append(tuple(sign if i == axis else (-mu if i == 2 else 0.0)
                                   for i in range(3)))
                moment.append((0.0, 0.0, 0.0))
    limits = [(0, half_width_m), (1, half_length_m)]
    if torsion_m is not None:
        limits.append((2, torsion_m))
    for axis, half in limits:
        for sign in (1.0, -1.0):
            force.append((0.0, 0.0, -half))
            moment.append(tuple(sign if i == axis else 0.0 for i in range(3)))
    return np.array(force), np.array(moment)


def _sole_rows(frame: np.ndarray, half_length_m: float, half_width_m: float,
               torsion_m: float | None, friction: float | None) -> np.ndarray:
    """The rows G (k, 6) of G [f, m] <= 0 that keep one sole's wrench feasible."""
    force, moment = _sole_coefficients(half_length_m, half_width_m, torsion_m, friction)
    return np.hstack([force @ frame, moment @ frame])


def solve_contact_qp(wrench: np.ndarray, split: np.ndarray, com: np.ndarray,
                     sole_centres: np.ndarray, frames: Sequence[np.ndarray | None],
                     sole_limits: tuple[float, float, float | None, float | None],
                     jacobians: np.ndarray, base_torque_nm: np.ndarray,
                     effort_limit_nm: np.ndarray) -> np.ndarray | None:
    """The soles' wrenches (2, 6) [f, m] (world, at `sole_centres` (2, 3)) making `wrench`
    (6,) [force, moment about `com`] as nearly as the constraints let them, near `split`
    (2, 6); `frames[foot]`: its contact frame (contact_frame), None for a sole that does
    not carry (its wrench 0); `sole_limits`: (half length, half width, torsion (m) or
    None, friction or None); `jacobians` (2, 6, 28) at the sole centres; the joints'
    torque is `base_torque_nm` - J^T x. None: no feasible wrench (or the solver failed)."""
    feet = [foot for foot in (0, 1) if frames[foot] is not None]
    result = np.zeros((2, 6))
    if not feet:
        return result
    count, size = len(feet), 6 * len(feet)
    makes = np.hstack([_wrench_map(sole_centres[foot] - com) for foot in feet])
    hessian = makes.T @ (_WEIGHT[:, None] * makes) + _REGULAR_DIAGONAL[count]
    linear = -(makes.T @ (_WEIGHT * wrench) + _REGULAR[count] * split[feet].reshape(size))
    transpose = jacobians[feet].reshape(size, -1).T  # (28, size)
    acted = np.flatnonzero(np.abs(transpose).sum(axis=1))
    blocks = [_sole_rows(frames[foot], *sole_limits) for foot in feet]
    sole_count = sum(len(block) for block in blocks)
    inequality = np.zeros((sole_count + 2 * len(acted), size))
    row = 0
    for column, block in enumerate(blocks):
        inequality[row:row + len(block), 6 * column:6 * column + 6] = block
        row += len(block)
    inequality[row:row + len(acted)] = -transpose[acted]
    inequality[row + len(acted):] = transpose[acted]
    limit, base = effort_limit_nm[acted], base_torque_nm[acted]
    bound = np.concatenate([np.zeros(sole_count), limit - base, limit + base])
    solution = qpsolvers.solve_qp(hessian, linear, inequality, bound, solver=QP_SOLVER)
    if solution is None:
        return None
    for column, foot in enumerate(feet):
        result[foot] = solution[6 * column:6 * column + 6]
    return result
