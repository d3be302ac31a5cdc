"""The swing foot's path: from where it lifts to where it lands, over the step's duration.

Horizontally and in yaw a quintic in the phase s = t / T (no speed and no acceleration at
lift-off or touchdown, so the foot neither scuffs nor slaps); vertically up to
`height_m` and down again along 64 s^3 (1 - s)^3, which also starts and ends at rest.
Between ends at different heights (`swing_height_m`) the lift is raised so that the apex
clears the higher end; on level ground it is SWING_HEIGHT_M. The sole turns from its
surface's tilt at lift-off to the landing surface's along the same quintic (a flat sole
landing up a 16 degree slope met it toes first, 3 cm short).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tutorial_atlas_control.walking.errors import WalkingError
from tutorial_atlas_control.walking.footsteps import wrap_angle

#: How high the swing foot's sole is lifted over the line between its ends (m).
SWING_HEIGHT_M = 0.08
#: A swing between ends at different heights (a slope, a ramp) passes at least this high
#: (m) over the higher end: where the ground bends between them (a ramp's top) it rises
#: above the line between the ends. Not more: 6 cm (the apex 0.12 m over the line up 16
#: degrees) and the swing leg, stretched up the slope, flailed at the fifth step and fell.
END_CLEARANCE_M = 0.03


def swing_height_m(start_z_m: float, end_z_m: float, lift_m: float = SWING_HEIGHT_M,
                   clearance_m: float = END_CLEARANCE_M) -> float:
    """How high (m) over the line between its ends a swing lifts the sole: `lift_m`, or more
    so that its apex (the line's middle plus that) is `clearance_m` over the higher end. On
    level ground (ends less than 2 (lift_m - clearance_m) apart in height) `lift_m` itself."""
    return max(lift_m, 0.5 * abs(end_z_m - start_z_m) + clearance_m)


def surface_tilt(normal: tuple[float, float, float]) -> tuple[float, float]:
    """The rotation (rad: a horizontal rotation vector's world x and y) that lays an upright
    sole on a surface of unit `normal`: about z x normal, by the angle between them; exactly
    (0, 0) for an upright normal."""
    normal_x, normal_y, normal_z = normal
    sine = math.hypot(normal_x, normal_y)
    if sine == 0.0:
        return 0.0, 0.0
    angle = math.atan2(sine, normal_z)
    return -normal_y / sine * angle, normal_x / sine * angle


def sole_frame(yaw_rad: float, tilt: tuple[float, float]) -> np.ndarray:
    """The frame (3, 3) of a sole heading `yaw_rad` laid on a surface by `tilt`
    (surface_tilt): the upright frame turned by the yaw, then tilted (Rodrigues' formula
    about the tilt's horizontal axis); the upright frame itself for no tilt."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    upright = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    tilt_x, tilt_y = tilt
    if tilt_x == 0.0 and tilt_y == 0.0:
        return upright
    angle = math.hypot(tilt_x, tilt_y)
    kx, ky = tilt_x / angle, tilt_y / angle
    ca, sa = math.cos(angle), math.sin(angle)
    v = 1.0 - ca
    tilted = np.array([[ca + kx * kx * v, kx * ky * v, ky * sa],
                       [kx * ky * v, ca + ky * ky * v, -kx * sa],
                       [-ky * sa, kx * sa, ca]])
    return tilted @ upright


def quintic(s: float) -> tuple[float, float, float]:
    """(value, d/ds, d2/ds2) of 10 s^3 - 15 s^4 + 6 s^5 on [0, 1]: 0 to 1 at rest."""
    s = min(max(s, 0.0), 1.0)
    return (s**3 * (10.0 - 15.0 * s + 6.0 * s * s),
            30.0 * s * s * (1.0 - s) ** 2,
            60.0 * s * (1.0 - s) * (1.0 - 2.0 * s))


def bump(s: float) -> tuple[float, float, float]:
    """(value, d/ds, d2/ds2) of 64 s^3 (1 - s)^3: 0 at both ends, 1 at s = 1/2, at rest at
    both ends."""
    s = min(max(s, 0.0), 1.0)
    u = s * (1.0 - s)
    du = 1.0 - 2.0 * s
    return 64.0 * u**3, 192.0 * u * u * du, 192.0 * (2.0 * u * du * du - 2.0 * u * u)


@dataclass(frozen=True)
class SwingPath:
    """A foot moved from `start` to `end` ((x, y, z) m and yaw rad, world) in `duration_s`."""

    start: np.ndarray   # (3,)
    end: np.ndarray     # (3,)
    start_yaw_rad: float
    end_yaw_rad: float
    duration_s: float
    height_m: float = SWING_HEIGHT_M
    #: The sole's tilt (surface_tilt) at lift-off and at touchdown: its surfaces'.
    start_tilt: tuple[float, float] = (0.0, 0.0)
    end_tilt: tuple[float, float] = (0.0, 0.0)

    def __post_init__(self) -> None:
        if not self.duration_s > 0.0:
            raise WalkingError(f'swing duration {self.duration_s} s is not positive')

    def tilt(self, t_s: float) -> tuple[float, float]:
        """The sole's tilt at `t_s` after lift-off: from the start's to the end's along the
        quintic (held at the ends)."""
        value = quintic(t_s / self.duration_s)[0]
        (start_x, start_y), (end_x, end_y) = self.start_tilt, self.end_tilt
        return start_x + value * (end_x - start_x), start_y + value * (end_y - start_y)

    def at(self, t_s: float) -> tuple[np.ndarray, np.ndarray, float, float]:
        """(position (3,), velocity (3,), yaw, yaw rate) of the sole at `t_s` after lift-off;
        held at the ends outside [0, duration]."""
        s = t_s / self.duration_s
        value, rate, _ = quintic(s)
        lift, lift_rate, _ = bump(s)
        delta = self.end - self.start
        position = self.start + value * delta
        position[2] += self.height_m * lift
        velocity = rate * delta / self.duration_s
        velocity[2] += self.height_m * lift_rate / self.duration_s
        if not 0.0 < s < 1.0:
            velocity[:] = 0.0
        turn = wrap_angle(self.end_yaw_rad - self.start_yaw_rad)
        yaw = wrap_angle(self.start_yaw_rad + value * turn)
        yaw_rate = rate * turn / self.duration_s if 0.0 < s < 1.0 else 0.0
        return position, velocity, yaw, yaw_rate

    def acceleration(self, t_s: float) -> tuple[np.ndarray, float]:
        """(acceleration (3,), yaw acceleration) of the sole at `t_s` after lift-off; zero
        outside (0, duration)."""
        s = t_s / self.duration_s
        if not 0.0 < s < 1.0:
            return np.zeros(3), 0.0
        per_s2 = 1.0 / (self.duration_s * self.duration_s)
        _, _, curve = quintic(s)
        _, _, lift_curve = bump(s)
        acceleration = curve * per_s2 * (self.end - self.start)
        acceleration[2] += self.height_m * lift_curve * per_s2
        turn = wrap_angle(self.end_yaw_rad - self.start_yaw_rad)
        return acceleration, curve * per_s2 * turn

