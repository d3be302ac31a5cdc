"""What the balance needs to know, computed from the simulator's own state.

The simulator knows its state exactly (no sensor noise), so the estimate is the model's
kinematics at the current joint positions and velocities, computed in a scratch MjData:
the stepping loop's MjData is not touched (after mj_step its body poses are those of the
step's start). One `estimate` call runs kinematics, MuJoCo's collision detection,
centre-of-mass and velocity passes and the bias forces (gravity and Coriolis) once.

Contact is MuJoCo's: which sole geoms touch which geoms of the world, where, with which
normals, from the contact list of the scratch data. The estimator keeps its own copy of the
model in which the soles' collision margin is CONTACT_HEIGHT_M, so a sole within that of any
surface (the plane today, a heightfield or a block tomorrow) is reported as touching, as the
balance has always counted it, while the simulation's own model, whose contacts push, is
left as it is (MuJoCo 4's `gap` no longer makes such contacts inactive: its contacts within
margin + gap all push). In that copy only the soles collide. Measured on the flat world:
mj_collision 8 us a call, which soles touch about 5 us more; their points and normals are
read only when asked for.

Within the simulator's step (estimate_stepped, sim.shared_passes) the compiled estimate
copies the kinematics, centres of mass, their velocities and the bias forces that the
step's mj_step1 has just computed at the same state from the simulator's MjData, and runs
only the soles' collision and the subtree velocity in its scratch data: the same numbers.

The per-tick work runs as one C call (compiled_estimator, src/atlas_estimator.c) when the
package's library is built, the Python below otherwise (after one warning) or when
ESTIMATOR_ENV says `python`: the reference the compiled one is tested against. The C call
also tests whether the support polygon last handed over still holds and makes the new hull
where it does not (bit for bit the Python's); which polygon was handed over, and so the
poses the next ticks are tested against, stays Python's to say, as the polygon is made only
when asked for. A compiled state's polygon, when kept, is in it from the start: the one
current at its estimate.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import mujoco
import numpy as np

from tutorial_atlas_control import native
from tutorial_atlas_control.balance import lipm, support
from tutorial_atlas_control.balance.compiled_estimator import (
    POLYGON_KEPT,
    SCALARS_AT,
    STATE_ARRAYS,
    CompiledEstimate,
    EstimatorGeometry,
    RawEstimate,
)
from tutorial_atlas_control.balance.sole import BOTTOM_CORNER_SIGNS, SoleBox, sole_geom_ids
from tutorial_atlas_control.sim import AtlasModel, passes_current

#: A sole within this of a surface (m) touches it and carries weight: the soles' collision
#: margin in the estimator's copy of the model.
CONTACT_HEIGHT_M = 0.01
#: The support polygon is recomputed once a sole corner has moved this far (m).
POLYGON_TOLERANCE_M = 5e-4
#: The pendulum's height is taken as at least this (m), so omega stays finite in a fall.
MIN_COM_HEIGHT_M = 0.05
#: Set to `python` to estimate in Python even where the compiled library is built.
ESTIMATOR_ENV = 'TAC_ESTIMATOR'


@dataclass(frozen=True)
class SoleContacts:
    """Where one sole touches the world, as MuJoCo's contact list says: a row per contact
    point within CONTACT_HEIGHT_M (world frame, m; normals point from the surface into the
    sole)."""

    points: np.ndarray    # (k, 3)
    normals: np.ndarray   # (k, 3) unit
    distances_m: np.ndarray  # (k,) signed gap, negative when pressed in
    surface_geoms: np.ndarray  # (k,) the world geoms touched

    @property
    def touching(self) -> bool:
        """Whether the sole touches anything."""
        return len(self.distances_m) > 0


def _no_contacts() -> SoleContacts:
    empty = np.zeros((0, 3))
    return SoleContacts(empty, empty, np.zeros(0), np.zeros(0, dtype=np.int64))


def _sole_contacts_of(sole: int, pairs: list[list[int]], distances: np.ndarray,
                      points: np.ndarray, normals: np.ndarray) -> SoleContacts:
    """One sole's rows of a copied contact list. MuJoCo's normal points from geom1 to geom2:
    into the sole when the sole is geom2."""
    rows = [row for row, pair in enumerate(pairs) if sole in pair]
    if not rows:
        return _no_contacts()
    signs = np.array([[1.0] if pairs[row][1] == sole else [-1.0] for row in rows])
    surfaces = np.array([pairs[row][0] if pairs[row][1] == sole else pairs[row][1]
                         for row in rows])
    return SoleContacts(points[rows], signs * normals[rows], distances[rows], surfaces)


def _contacts_of_raw(raw: RawEstimate) -> tuple[SoleContacts, SoleContacts]:
    """Both soles' contacts from the compiled estimate's rows."""
    left, right = raw.contact_rows()
    return _contacts_of_rows(left), _contacts_of_rows(right)


class _Cached:
    """A property made on first use and kept in the instance's __dict__: cached_property
    without the lock Python 3.11's takes at each first use (a few us a tick; making one
    twice from two threads gives equal values)."""

    def __init__(self, make: Callable[[Any], Any]) -> None:
        self._make = make
        self._name = make.__name__
        self.__doc__ = make.__doc__

    def __set_name__(self, owner: type, name: str) -> None:
        self._name = name

    def __get__(self, instance: Any, owner: type | None = None) -> Any:
        if instance is None:
            return self
        value = instance.__dict__[self._name] = self._make(instance)
        return value


def _contacts_of_rows(rows: np.ndarray) -> SoleContacts:
    """One sole's contacts from the compiled estimate's rows (point, normal into the sole,
    distance, surface geom), made without the frozen dataclass's __init__ (an
    object.__setattr__ a field): a walking tick's stance sole asks for them (sole_support)."""
    if len(rows) == 0:
        return _no_contacts()
    contacts = _new_object(SoleContacts)
    contacts.__dict__.update(points=rows[:, 0:3], normals=rows[:, 3:6], distances_m=rows[:, 6],
                             surface_geoms=rows[:, 7].astype(np.int64))
    return contacts


@dataclass(frozen=True)
class BalanceState:
    """The robot's balance-relevant state, world frame (m, m/s, rad/s)."""

    com: np.ndarray               # (3,) centre of mass
    com_velocity: np.ndarray      # (3,)
    pelvis_position: np.ndarray   # (3,)
    pelvis_rotation: np.ndarray   # (3, 3) pelvis frame to world
    pelvis_angular_velocity: np.ndarray  # (3,) world
    sole_centres: np.ndarray      # (2, 3) left, right: the middle of each sole's bottom face
    sole_rotations: np.ndarray    # (2, 3, 3)
    in_contact: tuple[bool, bool]
    omega: float                  # the LIPM's natural frequency at this CoM height (1/s)
    capture_point: np.ndarray     # (2,)
    bias_nm: np.ndarray           # (28,) joint part of qfrc_bias (gravity + Coriolis)
    sole_jacobians: np.ndarray    # (2, 6, 28) [linear; angular] at each sole centre, joints
    #: (2, 6) [linear; angular] velocity of each sole centre, world: the joints' and the
    #: floating base's motion both.
    sole_velocities: np.ndarray
    #: The joint-space inertia block (k, k) of some joints (a slice, tutorial order) at this
    #: state, computed on first use; valid until the estimator's next estimate.
    joint_inertia: Callable[[slice], np.ndarray]
    #: Makes support_polygon, on first use (Walk's single support never asks).
    polygon_of: Callable[[], np.ndarray]
    #: Makes sole_contacts, on first use (from this estimate's copy of the contact list).
    contacts_of: Callable[[], tuple[SoleContacts, SoleContacts]] = \
        lambda: (_no_contacts(), _no_contacts())
    #: The address of the compiled estimate's row holding these numbers, which the compiled
    #: whole-body tick reads in place: set in the instance by the compiled estimate only, not
    #: a field (so a state from __init__ or dataclasses.replace has None: its fields copied).
    row_address: ClassVar[int | None] = None
    #: The compiled estimate's model and scratch data (their addresses), nv, each joint's
    #: dof (tutorial order) and the address of its flag saying the scratch's mass matrix is
    #: the state's already (copied from the step; else mj_crb): the mass matrix of this
    #: state, which Walk's compiled legs read before the next estimate; set as row_address
    #: is (None: not compiled).
    mass_matrix_source: ClassVar[tuple[int, int, int, np.ndarray, int] | None] = None
    #: The compiled estimate's scratch qpos and qvel (the state's, until the next estimate)
    #: and each joint's qpos and dof address (tutorial order): the compiled whole body reads
    #: the joints there for JOINTS_IN_CALL; set as row_address is.
    joint_source: ClassVar[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None] = None

    def sole_bearing(self, foot: int) -> list[float] | None:
        """Where the sole `foot` bears as the compiled estimate summed it up with its
        contacts (compiled_estimator.BEARING_AT's five numbers: across facets 1.0 or 0.0,
        the box of its bearing contacts); None: not summed up (a Python estimate's state,
        or one made from fields), walking/sole_support then reads sole_contacts."""
        return None

    @_Cached
    def sole_contacts(self) -> tuple[SoleContacts, SoleContacts]:
        """Each sole's contacts (left, right), from MuJoCo's contact list."""
        return self.contacts_of()

    @_Cached
    def support_polygon(self) -> np.ndarray:
        """(k, 2) the convex hull of the soles in contact, counter-clockwise."""
        return self.polygon_of()


_new_object = object.__new__
#: Where each of a compiled estimate's arrays is among its block's views.
_ROW_VIEWS = {name: index for index, name in enumerate(STATE_ARRAYS)}


class _RowState(BalanceState):
    """A compiled estimate's BalanceState: its arrays, views of its row, made on first read
    and kept (a walking tick with a foot in the air reads none of them: its C calls read the
    row in place). Its scalars, callables and addresses are set at the estimate."""

    def __getattr__(self, name: str) -> Any:
        values = self.__dict__
        raw = values.get('_raw')
        index = _ROW_VIEWS.get(name)
        if raw is None:
            raise AttributeError(name)
        block, tick = raw.block, raw.tick
        if index is not None:
            view = block.fields[index][tick]
        elif name == 'bias_nm':
            view = block.bias[tick]
        elif name == 'sole_jacobians':
            view = block.jacobians[tick]
        else:
            raise AttributeError(name)
        values[name] = view
        return view

    def sole_bearing(self, foot: int) -> list[float] | None:
        """BalanceState.sole_bearing: the row's, when this state is the estimate's own."""
        raw = self.__dict__.get('_raw')
        return None if raw is None else raw.bearing(foot)


def _within(difference: np.ndarray, tolerance: float) -> bool:
    """Whether every element of `difference` is within +-`tolerance` (NaN: not): the
    test of float(np.max(np.abs(difference))) < tolerance, in plain floats (a third of its
    time for a few elements, each tick). min and max skip a NaN their sum keeps."""
    values = difference.ravel().tolist()
    return -tolerance < min(values) and max(values) < tolerance and not math.isnan(sum(values))


def _sized_as(model: mujoco.MjModel, data: mujoco.MjData) -> bool:
    """Whether `data` is of a model sized as `model` in every array the compiled estimate
    copies from a simulator's MjData (atlas_estimate_stepped)."""
    sizes = (data.qpos.shape[0], data.qvel.shape[0], data.xpos.shape[0], data.xanchor.shape[0],
             data.geom_xpos.shape[0], data.site_xpos.shape[0], data.M.shape[0])
    return sizes == (model.nq, model.nv, model.nbody, model.njnt, model.ngeom, model.nsite,
                     model.nC)


def _bodies_collide_as_their_geoms(model: mujoco.MjModel) -> None:
    """Each body's contype and conaffinity set to its geoms' (their bitwise or), as the
    compiler makes them: the broad phase skips a body by these, so a copy whose geoms were
    switched off there still sorted every robot body (mj_collision 14.6 us a call on the
    flat world, 5.5 us once they say none collides; the same contacts, bit for bit)."""
    contype = np.zeros(model.nbody, dtype=model.body_contype.dtype)
    conaffinity = np.zeros(model.nbody, dtype=model.body_conaffinity.dtype)
    np.bitwise_or.at(contype, model.geom_bodyid, model.geom_contype)
    np.bitwise_or.at(conaffinity, model.geom_bodyid, model.geom_conaffinity)
    model.body_contype[:] = contype
    model.body_conaffinity[:] = conaffinity


def _collide_soles_only(model: mujoco.MjModel, pelvis_body_id: int, soles: Sequence[int]
                        ) -> None:
    """The estimator's copy of the model made to find the soles' contacts alone, near ones
    included: the soles' margin CONTACT_HEIGHT_M (the copy pushes nothing); the robot's other
    geoms colliding with nothing (mj_collision 11 us a call with them, about 4 without); nor
    the world with itself (a course's loose blocks on its heightfield: hundreds of contacts
    a call), the soles still meeting all of it. No midphase: it tests a body of several geoms
    (a foot: its sole and the sole's corner spheres) by bounding boxes compiled without the
    margin set here, and a sole 0.4 mm into the floor went unseen."""
    model.geom_margin[soles] = CONTACT_HEIGHT_M
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_MIDPHASE
    robot = model.body_rootid[model.geom_bodyid] == pelvis_body_id
    others = np.flatnonzero(robot)
    others = others[~np.isin(others, soles)]
    model.geom_contype[others] = 0
    model.geom_conaffinity[others] = 0
    model.geom_contype[~robot] = 0
    _bodies_collide_as_their_geoms(model)


class BalanceEstimator:
    """Turns (qpos, qvel) into a BalanceState with a scratch MjData of its own.

    `compiled`: one C call a tick when the library is built (None: unless ESTIMATOR_ENV
    says `python`); False: the Python reference.
    """

    def __init__(self, atlas: AtlasModel, compiled: bool | None = None) -> None:
        self.atlas = atlas
        # A copy, so that the soles' wider margin finds near contacts without pushing.
        self.model = copy.deepcopy(atlas.model)
        self.scratch = mujoco.MjData(self.model)
        self.mass_kg = float(self.model.body_subtreemass[atlas.pelvis_body_id])  # the robot's
        self._soles = sole_geom_ids(self.model)
        self.sole = SoleBox.of(self.model)
        _collide_soles_only(self.model, atlas.pelvis_body_id, self._soles)
        self._sole_bodies = [int(self.model.geom_bodyid[g]) for g in self._soles]
        self._pelvis = atlas.pelvis_body_id
        self._jac = np.zeros((2, 6, self.model.nv))  # [linear; angular] per sole
        self._dof_adr = atlas.dof_adr
        self._bias = np.zeros(self.model.nv)
        self._free_dof = int(self.model.jnt_dofadr[self.model.body_jntadr[self._pelvis]])
        self._corner_offsets = np.array([BOTTOM_CORNER_SIGNS * self.model.geom_size[g]
                                         for g in self._soles])
        self._half_thickness = self.model.geom_size[self._soles, 2][:, None]
        # A sole turned this much (rotation matrix entries) moves a corner the tolerance.
        sole = self.sole
        self._rotation_tolerance = POLYGON_TOLERANCE_M / float(np.linalg.norm(
            [sole.half_length_m, sole.half_width_m, sole.half_thickness_m]))
        self._last_polygon: (tuple[tuple[bool, bool], np.ndarray, np.ndarray, np.ndarray]
                             | None) = None
        #: How many polygons were handed over: a compiled estimate's new polygon is valid
        #: while none was handed over since.
        self._polygons_held = 0
        self._held_polygon_of: Callable[[], np.ndarray] = lambda: np.zeros((0, 2))
        self._inertia_of = self._joint_inertia
        self._inertia = np.zeros((self.model.nv, self.model.nv))
        self._inertia_current = False
        #: Each joint slice's dof indices: a slice where they run on (a leg's do), else
        #: an index array.
        self._inertia_index: dict[tuple[int, int], tuple[slice, slice] | tuple] = {}
        self._sized_data: mujoco.MjData | None = None  # the last found _sized_as the copy
        self._sized_address = 0  # its address, for the compiled estimate
        self._ground_m = 0.0
        library = native.chosen_library(ESTIMATOR_ENV, compiled)
        self._kernel = None if library is None else CompiledEstimate(
            library, self.model, self.scratch, EstimatorGeometry(
                (self._soles[0], self._soles[1]), (self._sole_bodies[0], self._sole_bodies[1]),
                (float(self._half_thickness[0, 0]), float(self._half_thickness[1, 0])),
                self._pelvis, self._free_dof, np.asarray(self._dof_adr, dtype=np.intp),
                lipm.GRAVITY_M_S2, MIN_COM_HEIGHT_M, self._corner_offsets,
                POLYGON_TOLERANCE_M, self._rotation_tolerance))
        self._joint_source = (self.scratch.qpos, self.scratch.qvel,
                              np.asarray(atlas.qpos_adr, dtype=np.intp),
                              np.asarray(self._dof_adr, dtype=np.intp))
        self._mass_matrix_source = (
            self.model._address, self.scratch._address, int(self.model.nv),
            np.asarray(self._dof_adr, dtype=np.intp),
            0 if self._kernel is None else self._kernel.mass_current_address)

    @property
    def compiled(self) -> bool:
        """Whether estimate runs the C call."""
        return self._kernel is not None

    @property
    def ground_m(self) -> float:
        """The ground the pendulum stands on (m, world z): omega is that of the CoM's height
        over it. 0 unless a walk sets it: on a slope the feet's surface moves away from z 0
        (20 steps down 8 degrees: 0.56 m), and the capture point with omega of the CoM's
        world height ran ahead of the feet until the walk fell."""
        return self._ground_m

    @ground_m.setter
    def ground_m(self, height_m: float) -> None:
        self._ground_m = float(height_m)
        if self._kernel is not None:
            self._kernel.set_ground(self._ground_m)

    @property
    def sole_ahead_m(self) -> float:
        """How far ahead of its foot link's origin (the ankle) a sole's centre lies (m),
        along the foot: the model's."""
        return self.sole.ahead_m

    @property
    def sole_half_size_m(self) -> tuple[float, float]:
        """(half length, half width) of a sole box (m): the model's."""
        return self.sole.half_size_m

    def _support_polygon(self, positions: np.ndarray, rotations: np.ndarray,
                         contact: tuple[bool, bool]) -> np.ndarray:
        """The hull of the touching soles' corners; the same array as last time while the
        contacts are the same and no sole moved POLYGON_TOLERANCE_M at its corners
        (standing feet do not move: the hull is not recomputed every step, and the
        controller can cache on it). `positions`, `rotations`: the sole boxes' poses."""
        last = self._last_polygon
        if (last is not None and last[0] == contact
                and _within(positions - last[1], POLYGON_TOLERANCE_M)
                and _within(rotations - last[2], self._rotation_tolerance)):
            return last[3]
        corners = positions[:, None, 0:2] + np.einsum(
            'fcj,fij->fci', self._corner_offsets, rotations)[:, :, 0:2]
        touching = [foot for foot in (0, 1) if contact[foot]]
        polygon = (support.convex_hull(corners[touching].reshape(-1, 2)) if touching
                   else np.zeros((0, 2)))
        polygon.setflags(write=False)
        self._hold_polygon(contact, positions, rotations, polygon)
        return polygon

    def _hold_polygon(self, contact: tuple[bool, bool], positions: np.ndarray,
                      rotations: np.ndarray, polygon: np.ndarray) -> None:
        """Hand `polygon` over: the next estimates keep it while the soles stay within the
        tolerance of these poses (the compiled call tests that itself)."""
        self._last_polygon = (contact, positions, rotations, polygon)
        self._polygons_held += 1
        self._held_polygon_of = lambda: polygon
        if self._kernel is not None:
            self._kernel.hold_polygon(contact, positions, rotations)

    def _compiled_polygon(self, raw: RawEstimate, contact: tuple[bool, bool],
                          rotations: np.ndarray, held: int) -> np.ndarray:
        """A compiled estimate's new polygon, handed over on first use: the C call's hull
        while no other polygon was handed over since that estimate, else _support_polygon's
        test against the one that was (a state asked for after a later one)."""
        positions = raw.block.sole_positions[raw.tick]
        if held != self._polygons_held:
            return self._support_polygon(positions, rotations, contact)
        polygon = raw.polygon().copy()
        polygon.setflags(write=False)
        self._hold_polygon(contact, positions, rotations, polygon)
        return polygon

    def _joint_inertia(self, joints: slice) -> np.ndarray:
        """The inertia block of `joints` at the last estimate's state (mj_crb once per
        estimate, only when asked: Walk's swing leg needs it, Stand does not)."""
        if not self._inertia_current:
            mujoco.mj_crb(self.model, self.scratch)
            mujoco.mj_fullM(self.model, self.scratch, self._inertia)
            self._inertia_current = True
        key = (joints.start, joints.stop)
        index = self._inertia_index.get(key)
        if index is None:
            dofs = self._dof_adr[joints]
            runs_on = bool(np.all(np.diff(dofs) == 1))
            index = ((slice(int(dofs[0]), int(dofs[-1]) + 1),) * 2 if runs_on
                     else np.ix_(dofs, dofs))
            self._inertia_index[key] = index
        return self._inertia[index]

    def _touching(self) -> tuple[tuple[bool, bool], Callable[[], tuple[SoleContacts,
                                                                        SoleContacts]]]:
        """Which soles touch (after mj_collision: every contact of a sole's pair is within
        its margin), and what makes their contacts from a copy of the list (in plain
        Python: numpy's calls on eight rows cost more than MuJoCo's collision)."""
        count = self.scratch.ncon
        if count == 0:
            return (False, False), lambda: (_no_contacts(), _no_contacts())
        contact = self.scratch.contact
        pairs = contact.geom[:count].tolist()
        left, right = self._soles
        touching = (any(left in pair for pair in pairs), any(right in pair for pair in pairs))
        if not (touching[0] or touching[1]):
            return touching, lambda: (_no_contacts(), _no_contacts())
        rows = (contact.dist[:count].copy(), contact.pos[:count].copy(),
                contact.frame[:count, 0:3].copy())
        return touching, lambda: (_sole_contacts_of(left, pairs, *rows),
                                  _sole_contacts_of(right, pairs, *rows))

    def estimate(self, qpos: np.ndarray, qvel: np.ndarray) -> BalanceState:
        """The state at (qpos, qvel) (the full MuJoCo vectors)."""
        if self._kernel is None:
            return self._estimate_in_python(qpos, qvel)
        return self._state_of(self._kernel.run(qpos, qvel))

    def estimate_stepped(self, data: mujoco.MjData) -> BalanceState:
        """estimate(data.qpos, data.qvel), bit for bit, read from the simulator's own passes
        while its step has them current (sim.shared_passes: within a behaviour's torque)."""
        kernel = self._kernel
        if kernel is None or not passes_current(data):
            return self.estimate(data.qpos, data.qvel)
        if data is not self._sized_data:
            if not _sized_as(self.model, data):
                return self.estimate(data.qpos, data.qvel)
            self._sized_data, self._sized_address = data, data._address
        return self._state_of(kernel.run_stepped(self._sized_address))

    def _state_of(self, raw: RawEstimate) -> BalanceState:
        """The BalanceState of a compiled estimate's row (its arrays made on first read)."""
        self._inertia_current = False
        block, tick = raw.block, raw.tick
        scalars = block.array[tick, SCALARS_AT:POLYGON_KEPT + 1].tolist()
        contact = (scalars[0] != 0.0, scalars[1] != 0.0)
        state = _new_object(_RowState)
        values = state.__dict__
        if scalars[-1] != 0.0:  # the polygon last handed over holds: this state's too
            values['support_polygon'] = self._last_polygon[3]
            polygon_of = self._held_polygon_of
        else:
            held = self._polygons_held

            def polygon_of() -> np.ndarray:
                rotations = block.fields[_ROW_VIEWS['sole_rotations']][tick]
                return self._compiled_polygon(raw, contact, rotations, held)
        # The scalar fields without the frozen __init__ (an object.__setattr__ a field).
        values.update(
            in_contact=contact, omega=scalars[2], joint_inertia=self._inertia_of,
            polygon_of=polygon_of, contacts_of=lambda: _contacts_of_raw(raw),
            row_address=raw.address, mass_matrix_source=self._mass_matrix_source,
            joint_source=self._joint_source, _raw=raw)
        return state

    def _estimate_in_python(self, qpos: np.ndarray, qvel: np.ndarray) -> BalanceState:
        """estimate's reference: the same passes and arithmetic through the bindings."""
        m, d = self.model, self.scratch
        d.qpos[:] = qpos
        d.qvel[:] = qvel
        self._inertia_current = False
        mujoco.mj_kinematics(m, d)
        mujoco.mj_collision(m, d)
        mujoco.mj_comPos(m, d)
        mujoco.mj_comVel(m, d)
        mujoco.mj_subtreeVel(m, d)
        mujoco.mj_rne(m, d, 0, self._bias)
        positions = d.geom_xpos[self._soles]
        rotations = d.geom_xmat[self._soles].reshape(2, 3, 3)
        # Bottom-face centres (2, 3), world.
        centres = positions - rotations[:, :, 2] * self._half_thickness
        jac = self._jac
        for foot in (0, 1):
            mujoco.mj_jac(m, d, jac[foot, 0:3], jac[foot, 3:6], centres[foot],
                          self._sole_bodies[foot])
        sole_velocities = jac @ d.qvel
        contact, contacts_of = self._touching()
        com = d.subtree_com[self._pelvis].copy()  # the robot's, not a world's loose bodies'
        com_velocity = d.subtree_linvel[self._pelvis].copy()
        omega = lipm.natural_frequency(max(float(com[2]) - self._ground_m, MIN_COM_HEIGHT_M))
        free = self._free_dof
        pelvis_rotation = d.xmat[self._pelvis].reshape(3, 3).copy()
        return BalanceState(
            com=com, com_velocity=com_velocity,
            pelvis_position=d.xpos[self._pelvis].copy(), pelvis_rotation=pelvis_rotation,
            pelvis_angular_velocity=pelvis_rotation @ d.qvel[free + 3:free + 6],
            sole_centres=centres, sole_rotations=rotations, in_contact=contact, omega=omega,
            capture_point=lipm.capture_point(com[:2], com_velocity[:2], omega),
            bias_nm=self._bias[self._dof_adr], sole_jacobians=jac[:, :, self._dof_adr],
            sole_velocities=sole_velocities,
            joint_inertia=self._joint_inertia,
            polygon_of=lambda: self._support_polygon(positions, rotations, contact),
            contacts_of=contacts_of)
