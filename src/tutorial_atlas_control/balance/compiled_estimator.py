"""The balance estimator's per-tick work as one C call (src/atlas_estimator.c through ctypes).

estimator.BalanceEstimator.estimate in Python calls six MuJoCo passes and two jacobians, then
spends as long again in numpy's indexing and copies; the C twin runs the same passes on the
estimator's own model and scratch MjData (their C pointers) and writes every number of the
estimate into a flat row of its own per tick, whose slices become the BalanceState's fields
(a state never shares memory with the next). The same call tests whether the support polygon
last handed over still holds and, where it does not, makes the new one (its cache's reference
poses are set from Python, which alone knows which polygon was asked for). The library is
found and checked by tutorial_atlas_control.native; the estimator falls back to Python after
one warning without it. Both agree to rounding (test/unit/balance/test_compiled_estimator.py: 1e-9).
"""

from __future__ import annotations

import ctypes
import math
from dataclasses import dataclass

import mujoco
import numpy as np

from tutorial_atlas_control.balance.errors import BalanceError
from tutorial_atlas_control.balance.sole import ONE_SURFACE_COS, PRESSED_M, UPRIGHT_COS
from tutorial_atlas_control.native import AtlasEstimator, address

#: Sole contact rows the flat output holds (a box on a plane makes four a sole); more are
#: fetched by a second call.
CONTACT_CAPACITY = 32
#: A contact row: point (3), normal into the sole (3), signed distance, surface geom.
ROW = 8
#: The fixed part of the output (src/atlas_estimator.c's enum): name, offset, shape.
FIXED_FIELDS: tuple[tuple[str, int, tuple[int, ...]], ...] = (
    ('com', 0, (3,)), ('com_velocity', 3, (3,)), ('pelvis_position', 6, (3,)),
    ('pelvis_rotation', 9, (3, 3)), ('pelvis_angular_velocity', 18, (3,)),
    ('sole_positions', 21, (2, 3)), ('sole_centres', 27, (2, 3)),
    ('sole_rotations', 33, (2, 3, 3)), ('in_contact', 51, (2,)), ('omega', 53, ()),
    ('capture_point', 54, (2,)), ('sole_velocities', 56, (2, 6)))
#: Where the row's scalars read at once start: in_contact (2), omega, ... POLYGON_KEPT.
SCALARS_AT = 51
#: The support polygon's part of the output: 1.0 when the polygon last handed over holds,
#: else the vertex count and up to POLYGON_CAPACITY vertices (x, y).
POLYGON_KEPT, POLYGON_COUNT, POLYGON_AT = 68, 69, 70
#: Two soles' four corners.
POLYGON_CAPACITY = 8
#: Each sole's bearing summary (src/atlas_estimator.c's bearings, BEARING_SIZE doubles a
#: sole): 1.0 across facets, else 0.0; the box of its bearing contacts in its frame (m:
#: lowest, highest along; lowest, highest across; infinities with none). What
#: walking/sole_support.py's rule computes from the sole's contacts, made here with them.
BEARING_AT = POLYGON_AT + 2 * POLYGON_CAPACITY
BEARING_SIZE = 5
FIXED_SIZE = BEARING_AT + 2 * BEARING_SIZE
#: The FIXED_FIELDS a BalanceState holds as arrays, in the order of OutputBlock.fields (the
#: sole boxes' positions are read only for a new polygon; the scalars as one list).
STATE_ARRAYS = ('com', 'com_velocity', 'pelvis_position', 'pelvis_rotation',
                'pelvis_angular_velocity', 'sole_centres', 'sole_rotations', 'capture_point',
                'sole_velocities')
#: Ticks' outputs allocated at once.
BLOCK_TICKS = 64


def row_offsets(joints: int) -> dict[str, int]:
    """Where each of a BalanceState's arrays and omega start in a tick's row (doubles), for a
    call that reads the row in place (compiled_whole_body)."""
    offsets = {name: at for name, at, _ in FIXED_FIELDS}
    offsets['bias_nm'] = FIXED_SIZE
    offsets['sole_jacobians'] = FIXED_SIZE + joints
    return offsets


@dataclass(frozen=True)
class EstimatorGeometry:
    """What the C estimate needs to know of the model besides the model itself."""

    soles: tuple[int, int]          # sole geoms, left, right
    sole_bodies: tuple[int, int]
    half_thickness_m: tuple[float, float]
    pelvis: int
    free_dof: int
    dof_adr: np.ndarray             # (n,) intp
    gravity_m_s2: float
    min_com_height_m: float
    corner_offsets: np.ndarray      # (2, 4, 3) each sole's bottom corners in its frame
    polygon_tolerance_m: float      # a sole box's move that makes a new polygon
    rotation_tolerance: float       # its rotation entries' change that does


class RawEstimate:
    """One tick's numbers: row `tick` of `block` (its views across the ticks index it) at
    `address`, the sole contacts' count, and their rows when more than the row holds."""

    __slots__ = ('block', 'tick', 'address', 'total', 'overflow')

    def __init__(self, block: OutputBlock, tick: int, address: int, total: int,
                 overflow: np.ndarray | None) -> None:
        self.block, self.tick, self.address = block, tick, address
        self.total, self.overflow = total, overflow

    def contact_rows(self) -> tuple[np.ndarray, np.ndarray]:
        """Each sole's contact rows (k, ROW): left, right."""
        block, tick = self.block, self.tick
        rows = block.rows[tick, :self.total] if self.overflow is None else self.overflow
        left = int(block.counts[tick, 0])
        return rows[:left], rows[left:]

    def bearing(self, foot: int) -> list[float]:
        """The sole `foot`'s bearing summary (BEARING_AT's), as floats."""
        return self.block.bearings[self.tick, foot].tolist()

    def polygon(self) -> np.ndarray:
        """The new support polygon's vertices (a view: valid when not kept)."""
        return self.block.polygons[self.tick, :int(self.block.array[self.tick, POLYGON_COUNT])]


class OutputBlock:
    """BLOCK_TICKS ticks' outputs in one array, with each field's view across the ticks made
    once: a tick's fields are then one index each, and no tick shares memory with another
    (a state kept for later is never overwritten)."""

    def __init__(self, size: int, joints: int) -> None:
        self.array = np.empty((BLOCK_TICKS, size))
        self.base = self.array.ctypes.data
        self.next = 0
        array = self.array
        views = {name: array[:, at:at + math.prod(shape)].reshape((BLOCK_TICKS, *shape))
                 for name, at, shape in FIXED_FIELDS}
        #: STATE_ARRAYS' views, in their order.
        self.fields = tuple(views[name] for name in STATE_ARRAYS)
        self.sole_positions = views['sole_positions']
        self.polygons = array[:, POLYGON_AT:BEARING_AT].reshape(BLOCK_TICKS, POLYGON_CAPACITY, 2)
        self.bearings = array[:, BEARING_AT:FIXED_SIZE].reshape(BLOCK_TICKS, 2, BEARING_SIZE)
        jac_at, counts_at = FIXED_SIZE + joints, FIXED_SIZE + 13 * joints
        self.bias = array[:, FIXED_SIZE:jac_at]
        self.jacobians = array[:, jac_at:counts_at].reshape(BLOCK_TICKS, 2, 6, joints)
        self.counts = array[:, counts_at:counts_at + 2]
        self.rows = array[:, counts_at + 2:].reshape(BLOCK_TICKS, CONTACT_CAPACITY, ROW)


class CompiledEstimate:
    """atlas_estimate for one model, scratch MjData and geometry, as a single C call.

    Holds the model, data and scratch arrays so that the pointers given to C outlive it;
    MjData's arrays never move. The state is copied into arrays of its own, whose addresses
    C keeps; each tick writes the next row of an OutputBlock.
    """

    def __init__(self, library: ctypes.CDLL, model: mujoco.MjModel, data: mujoco.MjData,
                 geometry: EstimatorGeometry) -> None:
        self._library = library
        count = len(geometry.dof_adr)
        self._dof_adr = np.ascontiguousarray(geometry.dof_adr, dtype=np.intp)
        self._jac = np.zeros((2, 6, model.nv))
        self._bias = np.zeros(model.nv)
        self._qpos, self._qvel = np.zeros(model.nq), np.zeros(model.nv)
        self._keep = (model, data)
        kernel = self._kernel = AtlasEstimator()
        kernel.model, kernel.data = model._address, data._address
        kernel.qpos = address(self._qpos, np.float64)
        kernel.qvel = address(self._qvel, np.float64)
        kernel.dof_adr = address(self._dof_adr, np.intp)
        kernel.jac = address(self._jac, np.float64)
        kernel.bias = address(self._bias, np.float64)
        kernel.half_thickness[:] = geometry.half_thickness_m
        kernel.gravity_m_s2 = geometry.gravity_m_s2
        kernel.min_com_height_m = geometry.min_com_height_m
        kernel.ground_m = 0.0
        kernel.n = count
        kernel.soles[:] = geometry.soles
        kernel.sole_bodies[:] = geometry.sole_bodies
        kernel.pelvis = geometry.pelvis
        kernel.free_dof = geometry.free_dof
        kernel.contact_capacity = CONTACT_CAPACITY
        kernel.corner_offsets[:] = np.asarray(geometry.corner_offsets, dtype=np.float64).ravel()
        kernel.polygon_tolerance_m = geometry.polygon_tolerance_m
        kernel.rotation_tolerance = geometry.rotation_tolerance
        kernel.pressed_m, kernel.upright_cos = PRESSED_M, UPRIGHT_COS
        kernel.one_surface_cos = ONE_SURFACE_COS
        self._polygon_reference: tuple[np.ndarray, np.ndarray] | None = None
        self._pointer = ctypes.byref(kernel)
        self._estimate = library.atlas_estimate
        self._estimate_stepped = library.atlas_estimate_stepped
        self._count = count
        self._size = FIXED_SIZE + 13 * count + 2 + ROW * CONTACT_CAPACITY
        self._block = OutputBlock(self._size, count)
        self._row_bytes = 8 * self._size

    def hold_polygon(self, contact: tuple[bool, bool], positions: np.ndarray,
                     rotations: np.ndarray) -> None:
        """The poses and contacts the polygon just handed over was made from: the next
        calls test against them (kept here too, so that C's pointers stay valid)."""
        kernel = self._kernel
        kernel.polygon_positions = address(positions, np.float64)
        kernel.polygon_rotations = address(rotations, np.float64)
        kernel.polygon_contact[:] = contact
        self._polygon_reference = (positions, rotations)

    @property
    def mass_current_address(self) -> int:
        """The address of the call's flag saying its scratch data's mass matrix is the last
        estimate's state's (a stepped estimate copies the step's): Walk's legs read it."""
        return ctypes.addressof(self._kernel) + AtlasEstimator.mass_current.offset

    def set_ground(self, height_m: float) -> None:
        """The pendulum's ground (m, world z): omega is the CoM's height over it."""
        self._kernel.ground_m = height_m

    def run(self, qpos: np.ndarray, qvel: np.ndarray) -> RawEstimate:
        """The estimate at (qpos, qvel), the full MuJoCo vectors."""
        if np.shape(qpos) != self._qpos.shape or np.shape(qvel) != self._qvel.shape:
            raise BalanceError(f'qpos, qvel have shapes {np.shape(qpos)}, {np.shape(qvel)}; '
                               f'expected {self._qpos.shape}, {self._qvel.shape}')
        self._qpos[:] = qpos
        self._qvel[:] = qvel
        block, tick, row = self._next_row()
        return self._raw(block, tick, row, self._estimate(self._pointer))

    def run_stepped(self, stepped_address: int) -> RawEstimate:
        """The estimate at the state of an MjData (its address) whose position and velocity
        stages mj_step1 has just computed, for a model of the same sizes: those passes read,
        not run again (atlas_estimate_stepped)."""
        block = self._block
        tick = block.next
        if tick == BLOCK_TICKS:  # a new block: _next_row's
            block, tick, row = self._next_row()
            return self._raw(block, tick, row,
                             self._estimate_stepped(self._pointer, stepped_address))
        # _next_row and _raw inline: every tick of a walk, their calls cost as much as the
        # arithmetic
        block.next = tick + 1
        row = self._kernel.out = block.base + self._row_bytes * tick
        total = self._estimate_stepped(self._pointer, stepped_address)
        if total > CONTACT_CAPACITY:
            return self._raw(block, tick, row, total)
        return RawEstimate(block, tick, row, total, None)

    def _next_row(self) -> tuple[OutputBlock, int, int]:
        """The next tick's block, row index and row address (set as the kernel's output)."""
        block = self._block
        if block.next == BLOCK_TICKS:
            block = self._block = OutputBlock(self._size, self._count)
        tick = block.next
        block.next = tick + 1
        row = self._kernel.out = block.base + self._row_bytes * tick
        return block, tick, row

    def _raw(self, block: OutputBlock, tick: int, row: int, total: int) -> RawEstimate:
        """A tick's RawEstimate, the contact rows beyond the row's capacity fetched."""
        overflow = None
        if total > CONTACT_CAPACITY:
            overflow = np.empty((total, ROW))
            self._library.atlas_estimator_contacts(self._pointer, block.counts[tick].ctypes.data,
                                                   overflow.ctypes.data, total)
        return RawEstimate(block, tick, row, total, overflow)
