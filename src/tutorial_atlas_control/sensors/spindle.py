"""The laser's spindle (`hokuyo_joint`) as DRCSim's MultiSenseSL plugin drove it, kinematic.

The plugin velocity-PID'd the joint each 1 ms world update towards the commanded speed,
/multisense_sl/set_spindle_speed (rad/s, clamped to 0..50 RPM; 0 at start). The MuJoCo
model has no spindle joint (its 28 joints and every recorded bag depend on that), so the
joint is simulated here on its own: the plugin's PID (p 0.03, i 0.30, d 1e-5, its integral
term within +-1 N m and its command within +-10 N m) on hokuyo_link's inertia about the
spindle's axis (0.0004006 kg m2) with the URDF's joint damping (0.01 N m s), integrated at
the physics step. The ramp that gives: 80 % of a new speed within 30 ms (the proportional
term against the damping), the rest within 0.5 s (the integral's). The head's motion does not
drive it (Gazebo's does, through the joint's friction-free axis: negligible here).
No ROS, no MuJoCo.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ['MAX_SPINDLE_SPEED', 'MIN_SPINDLE_SPEED', 'Spindle', 'SpindleCommand',
           'spindle_command']

#: DRCSim's limits: spindleMaxRPM 50, spindleMinRPM 0 (rad/s).
MAX_SPINDLE_SPEED = 50.0 * 2.0 * math.pi / 60.0
MIN_SPINDLE_SPEED = 0.0
#: The plugin's spindlePID.Init(p, i, d, iMax, iMin, cmdMax, cmdMin).
PID_GAINS = (0.03, 0.30, 0.00001)
PID_I_LIMIT_NM = 1.0
PID_CMD_LIMIT_NM = 10.0
#: hokuyo_link's ixx (kg m2) in multisense_sl.urdf, and hokuyo_joint's damping (N m s/rad).
SPINDLE_INERTIA = 0.0004005974
SPINDLE_DAMPING = 0.01


@dataclass(frozen=True)
class SpindleCommand:
    """A set_spindle_speed message as taken: the speed to use (None: ignored) and, when the
    value was not taken as sent, the warning line saying what was done."""

    speed: float | None
    warning: str = ''


def spindle_command(value: float) -> SpindleCommand:
    """A set_spindle_speed value as DRCSim took it: clamped into [MIN, MAX] (infinities
    too); NaN, which DRCSim kept and its PID turned into NaN torques, is ignored."""
    if math.isnan(value):
        return SpindleCommand(None, 'ignored /multisense_sl/set_spindle_speed NaN (rad/s); '
                                    'the spindle keeps its speed')
    clamped = min(max(value, MIN_SPINDLE_SPEED), MAX_SPINDLE_SPEED)
    if clamped != value:
        return SpindleCommand(clamped, f'/multisense_sl/set_spindle_speed {value:g} rad/s '
                                       f'outside DRCSim\'s [{MIN_SPINDLE_SPEED:g}, '
                                       f'{MAX_SPINDLE_SPEED:.4f}]: clamped to {clamped:.4f}')
    return SpindleCommand(value)


class Spindle:
    """hokuyo_joint: its angle (rad, unbounded), speed (rad/s) and the PID's torque (N m),
    stepped once per physics step."""

    def __init__(self, dt_s: float) -> None:
        self.dt_s = dt_s
        self.target = 0.0
        self.angle = 0.0
        #: The angle before the last step (at the step's start, the time of its poses).
        self.previous_angle = 0.0
        self.velocity = 0.0
        self.effort = 0.0
        self._integral = 0.0
        self._last_error = 0.0

    def command(self, speed: float) -> None:
        """The speed to hold (rad/s; spindle_command's, within the limits)."""
        self.target = speed

    def step(self) -> None:
        """One physics step: the plugin's PID update, then the joint integrated (at rest and
        asked for 0, as at start, nothing changes: a test, not the arithmetic)."""
        if not (self.target or self.velocity or self._integral):
            self.previous_angle = self.angle
            return
        dt = self.dt_s
        p_gain, i_gain, d_gain = PID_GAINS
        error = self.velocity - self.target
        self._integral += dt * error
        i_term = i_gain * self._integral
        if abs(i_term) > PID_I_LIMIT_NM:
            i_term = math.copysign(PID_I_LIMIT_NM, i_term)
            self._integral = i_term / i_gain
        d_term = d_gain * (error - self._last_error) / dt
        self._last_error = error
        torque = -p_gain * error - i_term - d_term
        self.effort = min(max(torque, -PID_CMD_LIMIT_NM), PID_CMD_LIMIT_NM)
        self.velocity += dt * (self.effort - SPINDLE_DAMPING * self.velocity) / SPINDLE_INERTIA
        self.previous_angle = self.angle
        self.angle += dt * self.velocity

    @property
    def normalized_angle(self) -> float:
        """The angle in [-pi, pi), as the plugin's joint_states gave it (Angle::Normalize)."""
        return math.remainder(self.angle, 2.0 * math.pi) if self.angle else 0.0
