"""The swing foot's path: from where it lifts to where it lands, over the step's duration.

Horizontally and in yaw a quintic in the phase s = t / T (no speed and no acceleration at
lift-off or touchdown, so the foot neither scuffs nor slaps); vertically up to
`height_m` and down again along 64 s^3 (1 - s)^3, which also starts and ends at rest.
Between ends at different heights (`swing_height_m`) the lift is raised so that the apex
clears the higher end; on level ground it is SWING_HEIGHT_M.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tutorial_atlas_control.walking.errors import WalkingError
from tutorial_atlas_control.walking.footsteps import wrap_angle

#: How high the swing foot's sole is lifted over the line between its ends (m).
SWING_HEIGHT_M = 0.08
#: A swing between ends at different heights (a slope, a ramp) passes at least this high
#: (m) over the higher end: where the ground bends between them (a ramp's top or foot) it
#: rises above the line between the ends.
END_CLEARANCE_M = 0.06


def swing_height_m(start_z_m: float, end_z_m: float, lift_m: float = SWING_HEIGHT_M,
                   clearance_m: float = END_CLEARANCE_M) -> float:
    """How high (m) over the line between its ends a swing lifts the sole: `lift_m`, or more
    so that its apex (the line's middle plus that) is `clearance_m` over the higher end. On
    level ground (ends less than 2 (lift_m - clearance_m) apart in height) `lift_m` itself."""
    return max(lift_m, 0.5 * abs(end_z_m - start_z_m) + clearance_m)


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

    def __post_init__(self) -> None:
        if not self.duration_s > 0.0:
            raise WalkingError(f'swing duration {self.duration_s} s is not positive')

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

