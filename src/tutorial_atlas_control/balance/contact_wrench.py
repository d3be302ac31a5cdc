"""Sharing a desired total wrench between the two feet, within what each sole can push.

The feet's contact wrenches (ground on foot, at each sole centre, [f (3), m (3)], left then
right) must sum to the desired force F and moment M about the centre of mass. The moment
about the axis between the feet is made by shifting vertical load from one foot to the
other, as far as MIN_LOAD_SHARE left on the lighter foot (an unloaded foot would slide or
lift and land elsewhere): each foot takes the same share of F as of the vertical load.
What moment remains goes to the ankles in the same shares. Then each foot's share is made
feasible: no pull (f_z >= 0), the pressure centre inside the sole (|m_x| <= f_z w/2,
|m_y| <= f_z l/2 in the sole's frame) and, when asked, the force within friction.
In plain floats: this runs every 1 ms tick.
"""

from __future__ import annotations

import math

import numpy as np

Vector = tuple[float, float, float]

#: The least share of the load either foot keeps in double support (ours): enough
#: friction that a push does not drag the lighter foot along.
MIN_LOAD_SHARE = 0.1


def _cross(a: Vector, b: Vector) -> Vector:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _moment_about(point: Vector, com: Vector, force: Vector, moment: Vector) -> Vector:
    """A wrench's moment about `point`, given its moment about `com`."""
    lever = _cross((com[0] - point[0], com[1] - point[1], com[2] - point[2]), force)
    return (moment[0] + lever[0], moment[1] + lever[1], moment[2] + lever[2])


def left_share(force_n: Vector, moment_mid: Vector, left: Vector, right: Vector) -> float:
    """The left foot's share of the load that makes the moment about the axis between the
    feet (`moment_mid` being the moment about their midpoint), within MIN_LOAD_SHARE of
    0 and 1."""
    ux, uy = left[0] - right[0], left[1] - right[1]
    distance = math.hypot(ux, uy)
    if force_n[2] <= 0.0 or distance == 0.0:
        return 0.5
    # Vertical loads f_L, f_R at +-d/2 along u make (d/2)(f_L - f_R) about u x z.
    difference = 2.0 * (moment_mid[0] * uy - moment_mid[1] * ux) / (distance * distance)
    share = 0.5 + difference / (2.0 * force_n[2])
    return min(max(share, MIN_LOAD_SHARE), 1.0 - MIN_LOAD_SHARE)


def split_wrench(force_n: np.ndarray, moment_nm: np.ndarray, sole_centres: np.ndarray,
                 com: np.ndarray, in_contact: tuple[bool, bool]) -> np.ndarray:
    """(2, 6) contact wrenches [f, m] at the sole centres summing to (force_n, moment_nm)
    about `com`; a foot not in contact gets none."""
    force, moment = tuple(force_n.tolist()), tuple(moment_nm.tolist())
    centre = tuple(com.tolist())
    left, right = (tuple(row) for row in sole_centres.tolist())
    wrenches = np.zeros((2, 6))
    if in_contact[0] != in_contact[1]:
        foot = 0 if in_contact[0] else 1
        sole = left if foot == 0 else right
        wrenches[foot] = force + _moment_about(sole, centre, force, moment)
        return wrenches
    if not in_contact[0]:
        return wrenches
    middle = tuple((a + b) / 2.0 for a, b in zip(left, right))
    moment_mid = _moment_about(middle, centre, force, moment)
    share = left_share(force, moment_mid, left, right)
    shares = (share, 1.0 - share)
    made = [0.0, 0.0, 0.0]
    for foot, sole in ((0, left), (1, right)):
        foot_force = tuple(shares[foot] * f for f in force)
        lever = _cross(tuple(s - m for s, m in zip(sole, middle)), foot_force)
        made = [a + b for a, b in zip(made, lever)]
        wrenches[foot, 0:3] = foot_force
    rest = np.array(moment_mid) - made
    wrenches[0, 3:6] = share * rest
    wrenches[1, 3:6] = (1.0 - share) * rest
    return wrenches


def _within_friction(force: Vector, normal: Vector, friction: float) -> Vector:
    """`force` with its part along the surface (normal `normal`) scaled down to friction
    times its part pressing on it (none if it pulls)."""
    pressing = force[0] * normal[0] + force[1] * normal[1] + force[2] * normal[2]
    tangential = tuple(f - pressing * n for f, n in zip(force, normal))
    size = math.sqrt(tangential[0] ** 2 + tangential[1] ** 2 + tangential[2] ** 2)
    limit = friction * max(pressing, 0.0)
    if size <= limit:
        return force
    scale = 1.0 - limit / size
    return (force[0] - scale * tangential[0], force[1] - scale * tangential[1],
            force[2] - scale * tangential[2])


def make_feasible(wrench: np.ndarray, sole_rotation: np.ndarray,
                  half_length_m: float, half_width_m: float,
                  torsion_m: float | None = None, friction: float | None = None,
                  centre_m: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """`wrench` [f, m] (world) with f_z >= 0 and its pressure centre kept inside a sole of
    half sizes (half_length_m, half_width_m) (along the sole's x and y), or inside the
    rectangle of those half sizes about `centre_m` (along, across; sole frame) where only a
    part of the sole bears on the ground (walking/sole_support.py); with `torsion_m`,
    its moment about the sole's normal within torsion_m * f_z too (MuJoCo's torsional
    friction: more turns the foot on the ground); with `friction`, its force's part along
    the sole within friction times the part pressing on it (a cone about the sole's
    normal; without, friction is not modelled)."""
    fx, fy, fz, mx, my, mz = wrench.tolist()
    fz = max(fz, 0.0)
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = sole_rotation.tolist()
    if friction is not None:
        fx, fy, fz = _within_friction((fx, fy, fz), (r02, r12, r22), friction)
    # The moment in the sole's frame (R^T m), clamped, and back (R m).
    lx = r00 * mx + r10 * my + r20 * mz
    ly = r01 * mx + r11 * my + r21 * mz
    lz = r02 * mx + r12 * my + r22 * mz
    along, across = centre_m  # the pressure centre (-ly / fz, lx / fz) in the region
    lx = min(max(lx, fz * (across - half_width_m)), fz * (across + half_width_m))
    ly = min(max(ly, -fz * (along + half_length_m)), -fz * (along - half_length_m))
    if torsion_m is not None:
        lz = min(max(lz, -fz * torsion_m), fz * torsion_m)
    return np.array([fx, fy, fz, r00 * lx + r01 * ly + r02 * lz,
                     r10 * lx + r11 * ly + r12 * lz, r20 * lx + r21 * ly + r22 * lz])
