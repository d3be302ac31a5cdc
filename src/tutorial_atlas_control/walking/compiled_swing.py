"""The swing foot's servo as one C call (src/atlas_swing.c through ctypes).

LegTasks.swing_torque evaluates the swing path (its pose, velocity and acceleration) and
LegTasks.foot_servo turns the sole's pose error into the leg's torques through its damped
least-squares inverse and inertia: some sixty small numpy operations every swing tick in
Python, one call here. The state's numbers the servo reads (the sole's jacobian's leg
columns, its pose and velocity, the leg's rates and inertia) are copied into one input
array whose address C keeps. The library is found by tutorial_atlas_control.native; the
legs fall back to Python after one warning without it. Both agree to rounding
(test/unit/walking/test_compiled_swing.py: 1e-9).
"""

from __future__ import annotations

import ctypes
from typing import TYPE_CHECKING

import numpy as np

from tutorial_atlas_control.native import AtlasSwing, address

if TYPE_CHECKING:
    from tutorial_atlas_control.balance import BalanceState
    from tutorial_atlas_control.walking.leg_tasks import LegGains
    from tutorial_atlas_control.walking.swing import SwingPath

#: The input's size and layout (src/atlas_swing.c's enum).
IN_SIZE = 125
LEG = 6


class CompiledSwing:
    """atlas_swing_torque and atlas_foot_servo with `gains`, their buffers their own."""

    def __init__(self, library: ctypes.CDLL, gains: LegGains, joints: int) -> None:
        self._library = library
        self._joints = joints
        buffer = self._in = np.zeros(IN_SIZE)
        self._torque = np.zeros(LEG)
        self._jacobian = buffer[0:36].reshape(6, LEG)
        self._centre, self._rotation = buffer[36:39], buffer[39:48].reshape(3, 3)
        self._sole_velocity, self._joint_velocity = buffer[48:54], buffer[54:60]
        self._inertia = buffer[60:96].reshape(LEG, LEG)
        self._target = buffer[96:108]  # position, velocity, yaw, yaw rate, acceleration, ...
        self._path = buffer[108:119]   # start, end, their yaws, duration, height, time into it
        self._tilt = buffer[119:121]   # the target's tilt
        self._path_tilts = buffer[121:125]  # the path's tilts at lift-off and touchdown
        call = self._call = AtlasSwing()
        call.in_ = address(self._in, np.float64)
        call.torque = address(self._torque, np.float64)
        call.swing_kp, call.swing_kd = gains.swing_kp, gains.swing_kd
        call.damping = gains.ik_damping_m ** 2
        call.press_m = gains.swing_press_m
        call.touchdown_speed_m_s = gains.touchdown_speed_m_s
        self._feedforward = int(gains.swing_feedforward)
        self._world = int(gains.world_velocity)
        self._pointer = ctypes.byref(call)
        #: The path whose numbers the input holds (None: none yet).
        self._last_path: SwingPath | None = None

    @property
    def address(self) -> int:
        """The call's struct, for a call that runs the servo itself (compiled_legs)."""
        return ctypes.addressof(self._call)

    def set_path(self, swing: SwingPath) -> None:
        """The swing path's numbers into the input (unless they are there already: the
        package makes a new path to change one)."""
        if swing is self._last_path:
            return
        path = self._path
        path[0:3] = swing.start
        path[3:6] = swing.end
        path[6:10] = (swing.start_yaw_rad, swing.end_yaw_rad, swing.duration_s,
                      swing.height_m)
        self._path_tilts[:] = (*swing.start_tilt, *swing.end_tilt)
        self._last_path = swing

    def prepare_swing(self, elapsed_s: float) -> None:
        """The time into the path, and the swing's servo settings."""
        self._path[10] = elapsed_s
        call = self._call
        call.world, call.feedforward = self._world, self._feedforward

    def _load(self, state: BalanceState, joint_velocities: np.ndarray, leg: slice,
              foot: int) -> None:
        self._jacobian[:] = state.sole_jacobians[foot][:, leg]
        self._centre[:] = state.sole_centres[foot]
        self._rotation[:] = state.sole_rotations[foot]
        self._sole_velocity[:] = state.sole_velocities[foot]
        self._joint_velocity[:] = joint_velocities[leg]
        self._inertia[:] = state.joint_inertia(leg)

    def _result(self, leg: slice) -> np.ndarray:
        torque = np.zeros(self._joints)
        torque[leg] = self._torque
        return torque

    def swing_torque(self, state: BalanceState, joint_velocities: np.ndarray, leg: slice,
                     foot: int, swing: SwingPath, elapsed_s: float) -> np.ndarray:
        """LegTasks.swing_torque's torques (joints,), a new array."""
        self._load(state, joint_velocities, leg, foot)
        self.set_path(swing)
        self.prepare_swing(elapsed_s)
        self._library.atlas_swing_torque(self._pointer)
        return self._result(leg)

    def foot_servo(self, state: BalanceState, joint_velocities: np.ndarray, leg: slice,
                   foot: int, target: tuple[np.ndarray, np.ndarray, float, float,
                                            np.ndarray | None, float],
                   world: bool, tilt: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
        """LegTasks.foot_servo's torques (joints,), a new array; `target`: position,
        velocity, yaw, yaw rate, acceleration (None: none fed forward), yaw acceleration;
        `tilt`: the sole's (swing.surface_tilt)."""
        self._load(state, joint_velocities, leg, foot)
        position, velocity, yaw, yaw_rate, acceleration, yaw_acceleration = target
        values = self._target
        values[0:3] = position
        values[3:6] = velocity
        values[6], values[7] = yaw, yaw_rate
        values[8:11] = 0.0 if acceleration is None else acceleration
        values[11] = yaw_acceleration
        self._tilt[:] = tilt
        call = self._call
        call.world, call.feedforward = int(world), int(acceleration is not None)
        self._library.atlas_foot_servo(self._pointer)
        return self._result(leg)
