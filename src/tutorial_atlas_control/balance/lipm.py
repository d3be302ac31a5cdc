"""The linear inverted pendulum (LIPM) and its divergent component, the capture point.

With the centre of mass c at constant height z over a flat ground and the centre of
pressure p, the horizontal dynamics are c'' = omega^2 (c - p), omega = sqrt(g / z). The
capture point (divergent component of motion, DCM) xi = c + c' / omega obeys
xi' = omega (xi - p): it runs away from the centre of pressure, and the robot can stop
without stepping exactly when the centre of pressure can be put on it, i.e. when xi is
inside the support polygon. These are the textbook formulas (Pratt 2006, Englsberger 2011).
"""

from __future__ import annotations

import math
from typing import TypeVar

import numpy as np

from tutorial_atlas_control.balance.errors import BalanceError

#: A point on one axis (float: step_adjustment's per-axis arithmetic) or in the plane (m).
Point = TypeVar('Point', float, np.ndarray)

#: Standard gravity (m/s^2), the model's |gravity|.
GRAVITY_M_S2 = 9.81


def natural_frequency(com_height_m: float, gravity_m_s2: float = GRAVITY_M_S2) -> float:
    """omega = sqrt(g / z) (1/s) of a pendulum whose centre of mass is `com_height_m` up."""
    if not com_height_m > 0.0:
        raise BalanceError(f'centre-of-mass height {com_height_m} m must be above the ground')
    return math.sqrt(gravity_m_s2 / com_height_m)


def capture_point(com_xy: np.ndarray, com_velocity_xy: np.ndarray, omega: float) -> np.ndarray:
    """xi = c + c' / omega (m): where the centre of pressure must be to come to rest."""
    return np.asarray(com_xy) + np.asarray(com_velocity_xy) / omega


def lipm_state(com0: np.ndarray, velocity0: np.ndarray, cop: np.ndarray, omega: float,
               t_s: float) -> tuple[np.ndarray, np.ndarray]:
    """The LIPM's exact (c, c') after `t_s` with the centre of pressure held at `cop`.

    c(t) - p = (c0 - p) cosh(wt) + c0'/w sinh(wt); the reference for the tests.
    """
    offset = np.asarray(com0) - np.asarray(cop)
    wt = omega * t_s
    com = cop + offset * math.cosh(wt) + np.asarray(velocity0) / omega * math.sinh(wt)
    velocity = offset * omega * math.sinh(wt) + np.asarray(velocity0) * math.cosh(wt)
    return com, velocity


def capture_point_after(xi0: Point, cop: Point, omega: float, t_s: float) -> Point:
    """The capture point `t_s` after `xi0` with the pressure centre held at `cop` (m).

    xi(t) = p + (xi0 - p) exp(omega t), xi' = omega (xi - p) solved; a negative `t_s` runs
    it back: where the capture point must have been to reach `xi0` after -t_s.
    """
    return cop + (xi0 - cop) * math.exp(omega * t_s)


def cop_reaching(xi0: np.ndarray, xi_target: np.ndarray, omega: float,
                 t_s: float) -> np.ndarray:
    """The pressure centre that, held, takes the capture point from `xi0` to `xi_target` in
    `t_s` (m): capture_point_after solved for p, p = (xi_T - g xi0) / (1 - g),
    g = exp(omega t_s)."""
    growth = math.exp(omega * t_s)
    return (np.asarray(xi_target) - growth * np.asarray(xi0)) / (1.0 - growth)


def dcm_feedback_cop(xi: np.ndarray, xi_ref: np.ndarray, gain: float,
                     cop_ref: np.ndarray | None = None) -> np.ndarray:
    """The centre of pressure that makes the capture point converge to `xi_ref`.

    p = p_ref + (1 + gain) (xi - xi_ref) gives (xi - xi_ref)' = -omega gain (xi - xi_ref)
    for a reference moving as xi_ref' = omega (xi_ref - p_ref): with gain > 0 the error
    decays at rate omega * gain; with gain 0 it merely stops growing. Stand's reference is
    at rest (p_ref = xi_ref, the default: p = xi + gain (xi - xi_ref)); the walk's moves
    with its plan's pressure centre `cop_ref`.
    """
    (x, y), (x_ref, y_ref) = _plane(xi), _plane(xi_ref)
    p_x, p_y = (x_ref, y_ref) if cop_ref is None else _plane(cop_ref)
    factor = 1.0 + gain  # numpy's elementwise arithmetic in plain floats: every 1 ms tick
    return np.array([p_x + factor * (x - x_ref), p_y + factor * (y - y_ref)])


def _plane(point: np.ndarray) -> list[float]:
    """A point in the plane as two floats."""
    return np.asarray(point, dtype=np.float64).tolist()


def com_acceleration(com_xy: np.ndarray, cop_xy: np.ndarray, omega: float) -> np.ndarray:
    """c'' = omega^2 (c - p) (m/s^2): what a centre of pressure at `cop_xy` does."""
    return omega * omega * (np.asarray(com_xy) - np.asarray(cop_xy))
