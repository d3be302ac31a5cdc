"""The controller law as one compiled call per step (src/atlas_law.c through ctypes).

controller.compute_torque spends a few dozen numpy calls per step, each costing far more
than its arithmetic; the C twin does the same arithmetic in one call, reading q and v
straight from MjData and writing MjData.ctrl. The same call tests the state for
divergence (every qpos and qvel finite). The library is found and checked by
tutorial_atlas_control.native; without it the simulator runs the numpy law, after one
warning. Both give the same torques bit for bit (test/unit/sim/test_law_kernel.py), so a run,
its bag and its offline replay do not depend on which one ran.
"""

from __future__ import annotations

import ctypes
import functools
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from tutorial_atlas_control.command import LAW_FIELDS, JointCommandArrays
from tutorial_atlas_control.native import AtlasLawStep, address
from tutorial_atlas_control.sim.controller import PidState


@dataclass(frozen=True)
class LawJoints:
    """Where the law reads the joints (MjData's qpos and qvel, and each joint's address in
    them) and what bounds them, in the tutorial's joint order."""

    qpos: np.ndarray          # MjData.qpos
    qpos_adr: np.ndarray      # (28,) intp
    qvel: np.ndarray          # MjData.qvel
    dof_adr: np.ndarray       # (28,) intp
    lower: np.ndarray         # rad
    upper: np.ndarray         # rad
    effort_limit: np.ndarray  # N m
    dt_s: float

    def positions(self) -> np.ndarray:
        """The joint angles (rad, (28,), a new array)."""
        return self.qpos[self.qpos_adr]

    def velocities(self) -> np.ndarray:
        """The joint velocities (rad/s, (28,), a new array)."""
        return self.qvel[self.dof_adr]


class CompiledLaw:
    """compute_torque for one MjData, its joints and one PidState, as a single C call.

    Holds pointers into the arrays given here, and references to them so they outlive it;
    MjData's arrays never move, and PidState's are only ever written in place.
    """

    def __init__(self, library: ctypes.CDLL, joints: LawJoints, state: PidState,
                 torque: np.ndarray, ctrl: np.ndarray | None = None,
                 f_out: np.ndarray | None = None) -> None:
        """`ctrl`: also written with the torque; `f_out`: the torque (N m) blended in by
        1 - k_effort (None: 0), read at each call."""
        count = len(torque)
        for name, array in (('qpos_adr', joints.qpos_adr), ('dof_adr', joints.dof_adr),
                            ('lower', joints.lower), ('upper', joints.upper),
                            ('effort_limit', joints.effort_limit),
                            ('integral', state.integral),
                            ('previous_error', state.previous_error)):
            if array.shape != (count,):
                raise ValueError(f'{name} has shape {array.shape}, expected ({count},)')
        for name, optional in (('ctrl', ctrl), ('f_out', f_out)):
            if optional is not None and optional.shape != (count,):
                raise ValueError(f'{name} has shape {optional.shape}, expected ({count},)')
        self._keep = (joints, state, torque, ctrl, f_out)
        self.state = state
        step = self._step = AtlasLawStep()
        step.qpos = address(joints.qpos, np.float64)
        step.qpos_adr = address(joints.qpos_adr, np.intp)
        step.qvel = address(joints.qvel, np.float64)
        step.dof_adr = address(joints.dof_adr, np.intp)
        step.lower = address(joints.lower, np.float64)
        step.upper = address(joints.upper, np.float64)
        step.effort_limit = address(joints.effort_limit, np.float64)
        step.integral = address(state.integral, np.float64)
        step.previous_error = address(state.previous_error, np.float64)
        step.torque = address(torque, np.float64)
        step.ctrl = None if ctrl is None else address(ctrl, np.float64)
        step.f_out = None if f_out is None else address(f_out, np.float64)
        step.dt_s = joints.dt_s
        step.n = count
        step.nq, step.nv = joints.qpos.size, joints.qvel.size
        self._library = library
        self._call = library.atlas_law_step
        self._finite = library.atlas_state_is_finite
        self._pointer = ctypes.byref(step)
        self._command: JointCommandArrays | None = None
        self._command_arrays: tuple[np.ndarray, ...] = ()

    def __call__(self, command: JointCommandArrays) -> None:
        """One step of the law: torque (and ctrl) set, the PidState advanced."""
        if command is not self._command:
            self._bind(command)
        state = self.state
        step = self._step
        step.initialized = state.initialized
        self._call(self._pointer)
        state.initialized = True

    def state_is_finite(self) -> bool:
        """Every entry of qpos and qvel (the MjData arrays given) finite?"""
        return bool(self._finite(self._pointer))

    def unsound_call(self, numbers: np.ndarray, which: Sequence[int]) -> Callable[[], int]:
        """The divergence check's one call over this kernel's qpos and qvel and MuJoCo's
        warning counters `numbers` (MjData.warning.number, a view) at `which` (at most 4):
        0 when sound, 1 + the index in `which` of the first counter above 0, len(which) + 1
        when a value is not finite (atlas_step_unsound)."""
        item = numbers.itemsize
        if numbers.dtype != np.int32 or numbers.strides[0] % item or len(which) > 4:
            raise ValueError(f'warning counters of {numbers.dtype}, stride {numbers.strides}, '
                             f'{len(which)} tested')
        step = self._step
        step.warnings = numbers.ctypes.data
        step.warning_stride = numbers.strides[0] // item
        step.warning_count = len(which)
        step.warning_which[:len(which)] = which
        self._keep_unsound = numbers
        return functools.partial(self._library.atlas_step_unsound, self._pointer)

    def behaviour_call(self) -> Callable[[], None]:
        """A behaviour's torque, copied into this kernel's f_out, clamped there to the effort
        limits (numpy's maximum with their negatives, then minimum) and written to its torque
        and ctrl, in one call (atlas_behaviour_torque); the kernel must have an f_out."""
        if not self._step.f_out:
            raise ValueError('behaviour_call: this kernel has no f_out')
        return functools.partial(self._library.atlas_behaviour_torque, self._pointer)

    def _bind(self, command: JointCommandArrays) -> None:
        """Point the kernel at another command's arrays (a new command arrived)."""
        count = self._step.n
        block = command.rows_block()
        if block is not None and block.shape == (len(LAW_FIELDS), count):
            # One address for the ten rows (JointCommandArrays.copy: a new command's); the
            # block is kept, and with it every row the kernel points at.
            base, row_bytes = address(block, np.float64), block.strides[0]
            pointers = self._step.command
            for index in range(len(LAW_FIELDS)):
                pointers[index] = base + index * row_bytes
            self._command, self._command_arrays = command, (block,)
            return
        arrays = tuple(getattr(command, name) for name in LAW_FIELDS)
        for index, (name, array) in enumerate(zip(LAW_FIELDS, arrays)):
            if array.shape != (count,):
                raise ValueError(f'command.{name} has shape {array.shape}, expected ({count},)')
            self._step.command[index] = address(array, np.float64)
        self._command, self._command_arrays = command, arrays
