"""The controller law as one compiled call per step (src/atlas_law.c through ctypes).

Also compiled in that library, for the same reason (a numpy call costs about a
microsecond, the work a few nanoseconds): the divergence check's finiteness test, and the
indexed copies that fill the simulator's messages from MjData (CopyPlan, src/atlas_gather.c).

controller.compute_torque spends ~25 numpy calls per step, as much time as half a physics
step; the C twin does the same arithmetic in one call, reading q and v straight from
MjData and writing MjData.ctrl. It is built by catkin into the workspace's lib directory
(`make setup`); without it the simulator runs the numpy law, after one warning. Both give
the same torques bit for bit (test/unit/test_law_kernel.py), so a run, its bag and its
offline replay do not depend on which one ran.
"""

from __future__ import annotations

import ctypes
import os
import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from tutorial_atlas_control.msgs.commands import FIELD_NAMES, JointCommandArrays
from tutorial_atlas_control.sim.controller import PidState

#: The shared library CMakeLists.txt builds (devel/lib, installed to the package lib dir).
LIBRARY_NAME = 'libtutorial_atlas_control_law.so'
#: Set to a library path to use that one (or to a missing path to force the numpy law).
LIBRARY_ENV = 'TAC_LAW_LIBRARY'


class _Step(ctypes.Structure):
    """AtlasLawStep in src/atlas_law.c (same fields, same order)."""

    _fields_ = [
        ('command', ctypes.c_void_p * len(FIELD_NAMES)),
        ('qpos', ctypes.c_void_p), ('qpos_adr', ctypes.c_void_p),
        ('qvel', ctypes.c_void_p), ('dof_adr', ctypes.c_void_p),
        ('lower', ctypes.c_void_p), ('upper', ctypes.c_void_p), ('effort_limit', ctypes.c_void_p),
        ('integral', ctypes.c_void_p), ('previous_error', ctypes.c_void_p),
        ('torque', ctypes.c_void_p), ('ctrl', ctypes.c_void_p),
        ('dt_s', ctypes.c_double), ('n', ctypes.c_long), ('initialized', ctypes.c_long),
        ('nq', ctypes.c_long), ('nv', ctypes.c_long),
    ]


class _Copy(ctypes.Structure):
    """AtlasCopy in src/atlas_gather.c (same fields, same order)."""

    _fields_ = [('dst', ctypes.c_void_p), ('dst_index', ctypes.c_void_p),
                ('src', ctypes.c_void_p), ('src_index', ctypes.c_void_p),
                ('count', ctypes.c_long)]


def find_library() -> Path | None:
    """The compiled law: $TAC_LAW_LIBRARY if set, else the first catkin workspace's lib dir.

    The workspaces are those on CMAKE_PREFIX_PATH (set by `source ./env.sh` and inherited
    by roslaunch'd nodes), the same search catkin.find_in_workspaces does.
    """
    override = os.environ.get(LIBRARY_ENV)
    if override:
        path = Path(override)
        return path if path.is_file() else None
    for prefix in os.environ.get('CMAKE_PREFIX_PATH', '').split(os.pathsep):
        if prefix:
            path = Path(prefix) / 'lib' / LIBRARY_NAME
            if path.is_file():
                return path
    return None


_library: ctypes.CDLL | None = None
_warned = False


def load_library() -> ctypes.CDLL | None:
    """The loaded library, or None (warning once) when it is missing or does not load."""
    global _library, _warned
    if _library is not None:
        return _library
    path = find_library()
    override = os.environ.get(LIBRARY_ENV)
    problem = (f'{LIBRARY_ENV}={override} does not exist' if override
               else f'{LIBRARY_NAME} is not in the catkin workspace (run `make setup`)')
    if path is not None:
        try:
            library = ctypes.CDLL(str(path))
            library.atlas_law_step.argtypes = [ctypes.POINTER(_Step)]
            library.atlas_law_step.restype = None
            library.atlas_state_is_finite.argtypes = [ctypes.POINTER(_Step)]
            library.atlas_state_is_finite.restype = ctypes.c_int
            library.atlas_copy_all.argtypes = [ctypes.POINTER(_Copy), ctypes.c_long]
            library.atlas_copy_all.restype = None
            _library = library
            return library
        except (OSError, AttributeError) as err:
            problem = f'cannot load {path}: {err}'
    if not _warned:
        warnings.warn(f'{problem}; using the numpy controller law (same torques, slower)',
                      RuntimeWarning, stacklevel=2)
        _warned = True
    return None


def _address(array: np.ndarray, dtype: type) -> int:
    """Data pointer of a C-contiguous array of `dtype` (the kernel indexes it flat)."""
    if array.dtype != dtype or not array.flags.c_contiguous:
        raise ValueError(f'the compiled law needs C-contiguous {np.dtype(dtype)} arrays, '
                         f'got {array.dtype} (contiguous: {array.flags.c_contiguous})')
    return array.ctypes.data


class CompiledLaw:
    """compute_torque for one MjData, its joints and one PidState, as a single C call.

    Holds pointers into the arrays given here, and references to them so they outlive it;
    MjData's arrays never move, and PidState's are only ever written in place.
    """

    def __init__(self, library: ctypes.CDLL, qpos: np.ndarray, qpos_adr: np.ndarray,
                 qvel: np.ndarray, dof_adr: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                 effort_limit: np.ndarray, dt_s: float, state: PidState, torque: np.ndarray,
                 ctrl: np.ndarray | None = None) -> None:
        count = len(torque)
        for name, array in (('qpos_adr', qpos_adr), ('dof_adr', dof_adr), ('lower', lower),
                            ('upper', upper), ('effort_limit', effort_limit),
                            ('integral', state.integral),
                            ('previous_error', state.previous_error)):
            if array.shape != (count,):
                raise ValueError(f'{name} has shape {array.shape}, expected ({count},)')
        if ctrl is not None and ctrl.shape != (count,):
            raise ValueError(f'ctrl has shape {ctrl.shape}, expected ({count},)')
        self._keep = (qpos, qpos_adr, qvel, dof_adr, lower, upper, effort_limit, state, torque,
                      ctrl)
        self.state = state
        step = self._step = _Step()
        step.qpos = _address(qpos, np.float64)
        step.qpos_adr = _address(qpos_adr, np.intp)
        step.qvel = _address(qvel, np.float64)
        step.dof_adr = _address(dof_adr, np.intp)
        step.lower = _address(lower, np.float64)
        step.upper = _address(upper, np.float64)
        step.effort_limit = _address(effort_limit, np.float64)
        step.integral = _address(state.integral, np.float64)
        step.previous_error = _address(state.previous_error, np.float64)
        step.torque = _address(torque, np.float64)
        step.ctrl = None if ctrl is None else _address(ctrl, np.float64)
        step.dt_s = dt_s
        step.n = count
        step.nq, step.nv = qpos.size, qvel.size
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

    def _bind(self, command: JointCommandArrays) -> None:
        """Point the kernel at another command's arrays (a new command arrived)."""
        arrays = tuple(getattr(command, name) for name in FIELD_NAMES)
        count = self._step.n
        for name, array in zip(FIELD_NAMES, arrays):
            if array.shape != (count,):
                raise ValueError(f'command.{name} has shape {array.shape}, expected ({count},)')
            self._step.command[FIELD_NAMES.index(name)] = _address(array, np.float64)
        self._command, self._command_arrays = command, arrays


#: One copy of a CopyPlan: (dst, dst_index, src, src_index), meaning dst[dst_index] = src[src_index].
Copy = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


class CopyPlan:
    """A fixed list of indexed float64 copies, run together by one call.

    Compiled (one ctypes call) when the library is built, else numpy, one call per copy;
    the values copied are the same. Holds pointers into the arrays given and references to
    them: they must never be reallocated (MjData's arrays and wire.py's views are not).
    """

    def __init__(self, copies: Sequence[Copy], compiled: bool = True) -> None:
        """`compiled`: False always copies with numpy (the reference the C copies equal)."""
        self.copies = [(dst, np.ascontiguousarray(to, dtype=np.intp), src,
                        np.ascontiguousarray(source, dtype=np.intp))
                       for dst, to, src, source in copies]
        for dst, to, src, source in self.copies:
            if len(to) != len(source):
                raise ValueError(f'a copy of {len(source)} values to {len(to)} places')
            for name, array, index in (('dst', dst, to), ('src', src, source)):
                if len(index) and not 0 <= index.min() <= index.max() < array.size:
                    raise ValueError(f'{name} index outside 0..{array.size - 1}')
        library = load_library() if compiled else None
        self._call = None
        if library is not None:
            table = (_Copy * len(self.copies))()
            for entry, (dst, to, src, source) in zip(table, self.copies):
                entry.dst = _address(dst, np.float64)
                entry.dst_index = _address(to, np.intp)
                entry.src = _address(src, np.float64)
                entry.src_index = _address(source, np.intp)
                entry.count = len(to)
            self._table = table
            self._call = library.atlas_copy_all
            self._arguments = (table, len(table))

    def __call__(self) -> None:
        if self._call is not None:
            self._call(*self._arguments)
            return
        for dst, to, src, source in self.copies:
            dst[to] = src[source]
