"""The package's compiled library (src/atlas_law.c, src/atlas_gather.c,
src/atlas_estimator.c, src/atlas_statics.c, src/atlas_whole_body.c, src/atlas_swing.c,
src/atlas_legs.c, src/atlas_walk_swing.c): found, loaded, checked.

One place knows the library's binary interface: the ctypes mirrors of its structs, the
signatures of its functions, and where catkin puts it (a devel space's lib/ and an
install space's lib/ are both on CMAKE_PREFIX_PATH once their setup.bash is sourced).
Its users, the compiled law (sim/law_kernel.py), the messages' copies
(sim/copy_plan.py), the balance estimator (balance/compiled_estimator.py), the
whole-body layer's inverse statics (balance/compiled_statics.py), Stand's whole-body tick
around them (balance/compiled_whole_body.py), the swing foot's
servo (walking/compiled_swing.py), Walk's single-support tick of the legs around both
(walking/compiled_legs.py) and the walk's swing tick around that (walking/compiled_walk_swing.py),
ask here.
The estimator's part calls MuJoCo: the library is linked against the Python wheel's
libmujoco, the one `import mujoco` loads, so that one MuJoCo runs in the process.

A mirror that disagrees with the C struct would let C read or write past the fields
Python laid out, so the library exports `size_t tac_sizeof_<Struct>(void)` for each
mirrored struct, and a library whose sizes differ from the mirrors' (built from other
sources) is refused. Refused or missing, the callers fall back to numpy after one
warning, only slower: the law's torques bit for bit, the balance and walking ticks to
rounding (sums in another order, within 1e-9: test_compiled_*). A long walk on the course
feels that rounding: the deterministic finals_rubble walk from the rubble start walks
through with the library and falls at step 66 without it (their torques part by 3e-14 N m
at Stand's first tick), so a course figure is a fraction over seeds on one path.
"""

from __future__ import annotations

import ctypes
import os
import warnings
from pathlib import Path

import numpy as np

from tutorial_atlas_control.command import LAW_FIELDS

__all__ = ['LIBRARY_ENV', 'LIBRARY_NAME', 'MIRRORED_STRUCTS', 'AtlasCopy', 'AtlasEstimator',
           'AtlasHeightfield', 'AtlasLawStep', 'AtlasLegs', 'AtlasLegsSupport',
           'AtlasStatics', 'AtlasSwing', 'AtlasWalkSwing', 'AtlasWholeBody', 'address',
           'chosen_library', 'find_library', 'load_library', 'size_mismatches']

#: The shared library CMakeLists.txt builds (devel/lib, installed to the prefix's lib/).
LIBRARY_NAME = 'libtutorial_atlas_control_law.so'
#: Set to a library path to use that one (or to a missing path to force numpy).
LIBRARY_ENV = 'TAC_LAW_LIBRARY'
#: What the callers do without the library (the end of the one warning).
FALLBACK = ("using the numpy controller law (same torques, slower), the laser's numpy "
            'heightfield march, the Python swing-foot servo and the Python balance estimator, '
            'statics and whole-body tick')
#: How the library names the function that returns sizeof(Struct).
SIZEOF_PREFIX = 'tac_sizeof_'


class AtlasLawStep(ctypes.Structure):
    """AtlasLawStep in src/atlas_law.c (same fields, same order)."""

    _fields_ = [
        ('command', ctypes.c_void_p * len(LAW_FIELDS)),
        ('qpos', ctypes.c_void_p), ('qpos_adr', ctypes.c_void_p),
        ('qvel', ctypes.c_void_p), ('dof_adr', ctypes.c_void_p),
        ('lower', ctypes.c_void_p), ('upper', ctypes.c_void_p), ('effort_limit', ctypes.c_void_p),
        ('integral', ctypes.c_void_p), ('previous_error', ctypes.c_void_p),
        ('torque', ctypes.c_void_p), ('ctrl', ctypes.c_void_p), ('f_out', ctypes.c_void_p),
        ('dt_s', ctypes.c_double), ('n', ctypes.c_long), ('initialized', ctypes.c_long),
        ('nq', ctypes.c_long), ('nv', ctypes.c_long),
        ('warnings', ctypes.c_void_p), ('warning_stride', ctypes.c_long),
        ('warning_count', ctypes.c_long), ('warning_which', ctypes.c_long * 4),
    ]


class AtlasCopy(ctypes.Structure):
    """AtlasCopy in src/atlas_gather.c (same fields, same order)."""

    _fields_ = [('dst', ctypes.c_void_p), ('dst_index', ctypes.c_void_p),
                ('src', ctypes.c_void_p), ('src_index', ctypes.c_void_p),
                ('count', ctypes.c_long)]


class AtlasEstimator(ctypes.Structure):
    """AtlasEstimator in src/atlas_estimator.c (same fields, same order)."""

    _fields_ = [('model', ctypes.c_void_p), ('data', ctypes.c_void_p),
                ('qpos', ctypes.c_void_p), ('qvel', ctypes.c_void_p), ('out', ctypes.c_void_p),
                ('dof_adr', ctypes.c_void_p), ('jac', ctypes.c_void_p),
                ('bias', ctypes.c_void_p), ('half_thickness', ctypes.c_double * 2),
                ('gravity_m_s2', ctypes.c_double), ('min_com_height_m', ctypes.c_double),
                ('ground_m', ctypes.c_double),
                ('n', ctypes.c_long), ('soles', ctypes.c_long * 2),
                ('sole_bodies', ctypes.c_long * 2), ('pelvis', ctypes.c_long),
                ('free_dof', ctypes.c_long), ('contact_capacity', ctypes.c_long),
                ('polygon_positions', ctypes.c_void_p), ('polygon_rotations', ctypes.c_void_p),
                ('polygon_contact', ctypes.c_long * 2), ('polygon_tolerance_m', ctypes.c_double),
                ('rotation_tolerance', ctypes.c_double),
                ('corner_offsets', ctypes.c_double * 24), ('mass_current', ctypes.c_long),
                ('pressed_m', ctypes.c_double), ('upright_cos', ctypes.c_double),
                ('one_surface_cos', ctypes.c_double)]


class AtlasStatics(ctypes.Structure):
    """AtlasStatics in src/atlas_statics.c (same fields, same order)."""

    _fields_ = [('in_', ctypes.c_void_p), ('feet', ctypes.c_void_p),
                ('wrenches', ctypes.c_void_p), ('torque', ctypes.c_void_p),
                ('min_load_share', ctypes.c_double), ('n', ctypes.c_long)]


#: The estimate's fields atlas_whole_body.c reads from its row (WB_ROW_FIELDS).
WHOLE_BODY_ROW_FIELDS = 10


class AtlasWholeBody(ctypes.Structure):
    """AtlasWholeBody in src/atlas_whole_body.c (same fields, same order)."""

    _fields_ = [('statics', ctypes.c_void_p), ('in_', ctypes.c_void_p),
                ('reference', ctypes.c_void_p), ('gains', ctypes.c_void_p),
                ('joint_gains', ctypes.c_void_p), ('effort_limit', ctypes.c_void_p),
                ('region', ctypes.c_void_p), ('out', ctypes.c_void_p),
                ('region_count', ctypes.c_long), ('row', ctypes.c_void_p),
                ('row_at', ctypes.c_long * WHOLE_BODY_ROW_FIELDS),
                ('joint_qpos', ctypes.c_void_p), ('joint_qvel', ctypes.c_void_p),
                ('qpos_adr', ctypes.c_void_p), ('dof_adr', ctypes.c_void_p)]


class AtlasSwing(ctypes.Structure):
    """AtlasSwing in src/atlas_swing.c (same fields, same order)."""

    _fields_ = [('in_', ctypes.c_void_p), ('torque', ctypes.c_void_p),
                ('swing_kp', ctypes.c_double), ('swing_kd', ctypes.c_double),
                ('damping', ctypes.c_double), ('press_m', ctypes.c_double),
                ('touchdown_speed_m_s', ctypes.c_double), ('world', ctypes.c_long),
                ('feedforward', ctypes.c_long)]


class AtlasLegs(ctypes.Structure):
    """AtlasLegs in src/atlas_legs.c (same fields, same order)."""

    _fields_ = [('whole_body', ctypes.c_void_p), ('swing', ctypes.c_void_p),
                ('model', ctypes.c_void_p), ('data', ctypes.c_void_p),
                ('mass_matrix', ctypes.c_void_p), ('out', ctypes.c_void_p),
                ('reach', ctypes.c_double * 2), ('stance', ctypes.c_long),
                ('leg_start', ctypes.c_long), ('leg_dofs', ctypes.c_long * 6),
                ('sole_velocities_at', ctypes.c_long), ('row', ctypes.c_void_p),
                ('half_size', ctypes.c_double * 2), ('margin_m', ctypes.c_double),
                ('carrying', ctypes.c_long * 2), ('near_m', ctypes.c_double),
                ('bearing', ctypes.c_double * 4), ('mass_current', ctypes.c_void_p)]


class AtlasLegsSupport(ctypes.Structure):
    """AtlasLegsSupport in src/atlas_legs.h (same fields, same order)."""

    _fields_ = [('legs', ctypes.c_void_p), ('leg_starts', ctypes.c_long * 2),
                ('leg_dofs', (ctypes.c_long * 6) * 2), ('feet', (ctypes.c_double * 10) * 2),
                ('flat_height_m', ctypes.c_double), ('flat_cos', ctypes.c_double)]


class AtlasWalkSwing(ctypes.Structure):
    """AtlasWalkSwing in src/atlas_walk_swing.c (same fields, same order)."""

    _fields_ = [('legs', ctypes.c_void_p), ('out', ctypes.c_void_p),
                ('plan', ctypes.c_double * 5), ('plan_omega', ctypes.c_double),
                ('next_duration_s', ctypes.c_double), ('has_next', ctypes.c_long),
                ('step_duration_s', ctypes.c_double), ('dcm_gain', ctypes.c_double),
                ('tolerance_m', ctypes.c_double), ('planned', ctypes.c_double * 3),
                ('stance', ctypes.c_double * 3), ('limits', ctypes.c_double * 4),
                ('side', ctypes.c_double), ('step_xy', ctypes.c_double * 2),
                ('adjust', ctypes.c_long), ('elapsed_s', ctypes.c_double),
                ('time_s', ctypes.c_double), ('height', ctypes.c_double * 4),
                ('facing', ctypes.c_double * 4), ('rule_in_call', ctypes.c_long),
                ('near_cop_m', ctypes.c_double), ('bearing_at', ctypes.c_long)]


class AtlasHeightfield(ctypes.Structure):
    """AtlasHeightfield in src/atlas_heightfield.c (same fields, same order)."""

    _fields_ = [('heights', ctypes.c_void_p), ('tile_highest', ctypes.c_void_p),
                *((name, ctypes.c_long) for name in ('rows', 'cols', 'tile_rows', 'tile_cols',
                                                     'tile_cells', 'segment_steps')),
                *((name, ctypes.c_double) for name in ('centre_x', 'centre_y', 'half_x',
                                                       'half_y', 'lowest', 'highest', 'step_m',
                                                       'tol_m'))]


#: Every struct Python lays out for the library, by its C name: the library must export
#: SIZEOF_PREFIX + name, returning the same size as the mirror's.
MIRRORED_STRUCTS: dict[str, type[ctypes.Structure]] = {
    'AtlasLawStep': AtlasLawStep,
    'AtlasCopy': AtlasCopy,
    'AtlasEstimator': AtlasEstimator,
    'AtlasStatics': AtlasStatics,
    'AtlasSwing': AtlasSwing,
    'AtlasWholeBody': AtlasWholeBody,
    'AtlasLegs': AtlasLegs,
    'AtlasLegsSupport': AtlasLegsSupport,
    'AtlasWalkSwing': AtlasWalkSwing,
    'AtlasHeightfield': AtlasHeightfield,
}


def address(array: np.ndarray, dtype: type) -> int:
    """Data pointer of a C-contiguous array of `dtype`, for a mirrored struct's field.

    The library indexes each array flat, as that dtype; any other layout would be misread.
    """
    if array.dtype != dtype or not array.flags.c_contiguous:
        raise ValueError(f'the compiled library needs C-contiguous {np.dtype(dtype)} arrays, '
                         f'got {array.dtype} (contiguous: {array.flags.c_contiguous})')
    return array.ctypes.data


def find_library() -> Path | None:
    """The compiled library: $TAC_LAW_LIBRARY if set, else the first catkin prefix's lib/.

    The prefixes are those on CMAKE_PREFIX_PATH (set by a devel or install space's
    setup.bash, which `source ./env.sh` sources, and inherited by roslaunch'd nodes), the
    same search catkin.find_in_workspaces does.
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


def size_mismatches(library: ctypes.CDLL) -> list[str]:
    """One phrase per mirrored struct whose size the library does not report as the
    mirror's: a different size, or no size function (built from older sources)."""
    found = []
    for name, mirror in MIRRORED_STRUCTS.items():
        try:
            sizeof = getattr(library, SIZEOF_PREFIX + name)
        except AttributeError:
            found.append(f'no {SIZEOF_PREFIX}{name}()')
            continue
        sizeof.argtypes = []
        sizeof.restype = ctypes.c_size_t
        library_size, mirror_size = sizeof(), ctypes.sizeof(mirror)
        if library_size != mirror_size:
            found.append(f'sizeof({name}) is {library_size} bytes there, '
                         f'{mirror_size} in {__name__}')
    return found


def _declare(library: ctypes.CDLL) -> None:
    """The signatures of the library's functions (ctypes would guess int otherwise)."""
    library.atlas_law_step.argtypes = [ctypes.POINTER(AtlasLawStep)]
    library.atlas_law_step.restype = None
    library.atlas_state_is_finite.argtypes = [ctypes.POINTER(AtlasLawStep)]
    library.atlas_state_is_finite.restype = ctypes.c_int
    library.atlas_step_unsound.argtypes = [ctypes.POINTER(AtlasLawStep)]
    library.atlas_step_unsound.restype = ctypes.c_long
    library.atlas_behaviour_torque.argtypes = [ctypes.POINTER(AtlasLawStep)]
    library.atlas_behaviour_torque.restype = None
    library.atlas_copy_all.argtypes = [ctypes.POINTER(AtlasCopy), ctypes.c_long]
    library.atlas_copy_all.restype = None
    estimator = ctypes.POINTER(AtlasEstimator)
    library.atlas_estimate.argtypes = [estimator]
    library.atlas_estimate.restype = ctypes.c_long
    library.atlas_estimate_stepped.argtypes = [estimator, ctypes.c_void_p]
    library.atlas_estimate_stepped.restype = ctypes.c_long
    library.atlas_estimator_contacts.argtypes = [estimator, ctypes.c_void_p, ctypes.c_void_p,
                                                 ctypes.c_long]
    library.atlas_estimator_contacts.restype = ctypes.c_long
    library.atlas_inverse_statics.argtypes = [ctypes.POINTER(AtlasStatics)]
    library.atlas_inverse_statics.restype = None
    for name in ('atlas_whole_body', 'atlas_stand_tick'):
        function = getattr(library, name)
        function.argtypes = [ctypes.POINTER(AtlasWholeBody)]
        function.restype = None
    for name in ('atlas_foot_servo', 'atlas_swing_torque'):
        function = getattr(library, name)
        function.argtypes = [ctypes.POINTER(AtlasSwing)]
        function.restype = None
    for name in ('atlas_legs_swing_tick', 'atlas_legs_support_clamp'):
        function = getattr(library, name)
        function.argtypes = [ctypes.POINTER(AtlasLegs)]
        function.restype = None
    library.atlas_legs_support_tick.argtypes = [ctypes.POINTER(AtlasLegsSupport)]
    library.atlas_legs_support_tick.restype = None
    library.atlas_walk_swing_tick.argtypes = [ctypes.POINTER(AtlasWalkSwing)]
    library.atlas_walk_swing_tick.restype = None
    library.atlas_heightfield_distances.argtypes = [
        ctypes.POINTER(AtlasHeightfield), ctypes.c_void_p, ctypes.c_void_p, ctypes.c_long,
        ctypes.c_double, ctypes.c_void_p]
    library.atlas_heightfield_distances.restype = ctypes.c_long


_library: ctypes.CDLL | None = None
_warned = False


def load_library() -> ctypes.CDLL | None:
    """The loaded, checked library, or None (warning once) when it is missing, does not
    load, or does not match the mirrors here."""
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
            mismatches = size_mismatches(library)
            if not mismatches:
                _declare(library)
        except (OSError, AttributeError) as err:
            problem = f'cannot load {path}: {err}'
        else:
            if not mismatches:
                _library = library
                return library
            problem = (f'{path} does not match this code ({"; ".join(mismatches)}); '
                       'rebuild it (`make setup`)')
    if not _warned:
        warnings.warn(f'{problem}; {FALLBACK}', RuntimeWarning, stacklevel=2)
        _warned = True
    return None


def chosen_library(switch_env: str, compiled: bool | None) -> ctypes.CDLL | None:
    """The library for a part with a compiled and a Python path: None when `compiled` is
    False, or (`compiled` None) when the environment variable `switch_env` says `python`;
    else load_library()'s answer."""
    if compiled is None:
        compiled = os.environ.get(switch_env, '').strip().lower() != 'python'
    return load_library() if compiled else None
