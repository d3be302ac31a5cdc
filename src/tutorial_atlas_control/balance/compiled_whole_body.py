"""Stand's whole-body tick as one C call (src/atlas_whole_body.c through ctypes).

StandController.tick picks the pressure centre (the capture-point law, clamped into the
support polygon shrunk by the margin), builds the centroidal tasks and the posture task,
solves them by inverse statics and clamps the torques to the effort limits;
StandController.whole_body does the same at a given pressure centre without the clamp
(Walk's legs call it). In Python that is some two hundred small float and numpy operations
a tick, here one call around the inverse statics' own C (compiled_statics, whose input
buffer this fills). A state from the compiled estimator is read by C in place, from the
estimate's row (its address and the row's offsets: no copy in Python); any other state's
numbers are copied into the buffers whose addresses C keeps. The reference, the joint
gains and the support region are copied only when they are other objects than last tick's
(the package makes a new reference to change one, never writing into its arrays). Both
agree to rounding
(test/unit/balance/test_compiled_whole_body.py: 1e-9).
"""

from __future__ import annotations

import ctypes
import math
from typing import TYPE_CHECKING

import numpy as np

from tutorial_atlas_control.balance.compiled_estimator import row_offsets
from tutorial_atlas_control.balance.errors import BalanceError
from tutorial_atlas_control.balance.lipm import GRAVITY_M_S2
from tutorial_atlas_control.native import AtlasWholeBody, address

if TYPE_CHECKING:
    from tutorial_atlas_control.balance.compiled_statics import CompiledStatics
    from tutorial_atlas_control.balance.estimator import BalanceState
    from tutorial_atlas_control.balance.stand import MovedReference, StandGains, StandReference
    from tutorial_atlas_control.balance.support import Region
    from tutorial_atlas_control.balance.whole_body import ContactConstraint

#: The per-tick input's fixed part (src/atlas_whole_body.c's WB_IN_*): the pressure centre,
#: the capture point, omega, the CoM's velocity, the pelvis's rotation and angular velocity.
IN_FIXED = 20
#: The reference's fixed part (WB_REF_*): capture point, height, its rate, pelvis rotation,
#: pelvis angular velocity.
REFERENCE_FIXED = 16
#: Where a region row's fields sit: vertex x, y, then its edge's inward normal and offset.
REGION_ROW = 5
#: The state's fields C reads from the estimate's row, in the order of atlas_whole_body.c's
#: WB_ROW_* offsets (as many as native.WHOLE_BODY_ROW_FIELDS: ctypes refuses another count).
ROW_FIELDS = ('com', 'com_velocity', 'pelvis_rotation', 'pelvis_angular_velocity',
              'sole_centres', 'sole_rotations', 'omega', 'capture_point', 'bias_nm',
              'sole_jacobians')

#: load's `moved` when the caller's own C call writes the heading, height and rate over the
#: reference (Walk's swinging tick, compiled_walk_swing): compared by identity only.
MOVED_IN_CALL: MovedReference = (math.nan, math.nan, math.nan)

#: load's joint positions and velocities when the call reads them itself from the compiled
#: estimate's scratch data (the state's, at the joints' addresses): compared by identity only.
JOINTS_IN_CALL = np.empty(0)
JOINTS_IN_CALL.setflags(write=False)
#: BalanceState.joint_source: the estimate's scratch qpos, qvel, the joints' addresses in each.
JointSource = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _joint_source(state: BalanceState, row: int | None) -> JointSource:
    """Where JOINTS_IN_CALL's joints are for `state` (the estimate's `row`, None for a
    Python estimate's); refused for a state not of the compiled estimate."""
    source = state.joint_source
    if row is None or source is None:
        raise BalanceError('JOINTS_IN_CALL for a state not of the compiled estimate: pass '
                           'its joint positions and velocities')
    return source


def joints_of(state: BalanceState) -> tuple[np.ndarray, np.ndarray]:
    """The joint positions and velocities (tutorial order, new arrays) JOINTS_IN_CALL stands
    for: the compiled estimate's state's, as its callers' copies of the simulator's qpos and
    qvel were (the estimate copies those into its scratch data); for a Python path."""
    qpos, qvel, qpos_adr, dof_adr = _joint_source(state, state.row_address)
    return qpos[qpos_adr], qvel[dof_adr]

#: One tick's results: torque (n,), pressure centre (2,), force (3,), moment (3,) and the
#: soles' wrenches (2, 6), new arrays.
Tick = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]


def _kept_if_read_only(array: np.ndarray) -> np.ndarray | None:
    """`array` if nothing can write into it, not even through a base (its values then stay
    those copied), else None."""
    return None if array.flags.writeable or array.base is not None else array


class CompiledWholeBody:
    """atlas_stand_tick and atlas_whole_body over `statics`, with Stand's `gains` for a robot
    of `mass_kg` and its `effort_limit_nm`; its buffers its own."""

    def __init__(self, library: ctypes.CDLL, statics: CompiledStatics, mass_kg: float,
                 gains: StandGains, effort_limit_nm: np.ndarray) -> None:
        joints = len(effort_limit_nm)
        self._library = library
        self._statics = statics
        self._in = np.zeros(IN_FIXED + 2 * joints)
        self._reference = np.zeros(REFERENCE_FIXED + 2 * joints)
        self._gains = np.array([mass_kg, gains.capture_gain, gains.height_kp, gains.height_kd,
                                gains.orientation_kp, gains.orientation_kd, GRAVITY_M_S2])
        self._joint_gains = np.zeros(2 * joints)
        #: The joint_source the call reads the joints from (None: they are copied into _in).
        self._gathering: JointSource | None = None
        self._effort_limit = np.array(effort_limit_nm, dtype=np.float64)
        self._out = np.zeros(8)
        self._region = np.zeros((1, REGION_ROW))
        buffer = self._in
        self._cop, self._capture = buffer[0:2], buffer[2:4]
        self._com_velocity = buffer[5:8]
        self._pelvis_rotation = buffer[8:17].reshape(3, 3)
        self._pelvis_angular = buffer[17:20]
        self._joints = buffer[IN_FIXED:].reshape(2, joints)
        self._last_reference: StandReference | None = None
        #: The read-only rate arrays the buffer holds (None: a writable one, copied each time).
        self._rates: tuple[np.ndarray | None, np.ndarray | None] = (None, None)
        #: The heading, height and rate written over the last reference's (None: its own).
        self._last_moved: MovedReference | None = None
        self._last_gains: tuple[np.ndarray, np.ndarray] | None = None
        self._last_region: Region | None | bool = False
        call = self._call = AtlasWholeBody()
        call.statics = statics.address
        call.in_ = address(self._in, np.float64)
        call.reference = address(self._reference, np.float64)
        call.gains = address(self._gains, np.float64)
        call.joint_gains = address(self._joint_gains, np.float64)
        call.effort_limit = address(self._effort_limit, np.float64)
        call.region = address(self._region, np.float64)
        call.out = address(self._out, np.float64)
        offsets = row_offsets(joints)
        call.row_at[:] = [offsets[name] for name in ROW_FIELDS]
        self._pointer = ctypes.byref(call)

    def _set_reference(self, reference: StandReference) -> None:
        """The reference into the buffer; a rate array only when it is not the read-only
        one copied last (a take-over's every tick: its zeros are such arrays)."""
        joints = len(self._effort_limit)
        buffer = self._reference
        buffer[0:2] = reference.capture_point
        buffer[2:4] = (reference.com_height_m, reference.com_height_rate_m_s)
        buffer[4:13] = reference.pelvis_rotation.reshape(9)
        buffer[REFERENCE_FIXED:REFERENCE_FIXED + joints] = reference.posture_rad
        turn, posture = reference.pelvis_angular_velocity, reference.posture_rate_rad_s
        if turn is not self._rates[0]:
            buffer[13:16] = turn
        if posture is not self._rates[1]:
            buffer[REFERENCE_FIXED + joints:] = posture
        self._rates = (_kept_if_read_only(turn), _kept_if_read_only(posture))
        self._last_reference = reference
        self._last_moved = None

    def _move_reference(self, moved: MovedReference) -> None:
        """The reference's pelvis frame (upright, stand.yaw_rotation's numbers), CoM height
        and rate replaced in the buffer: stand.moved_reference without a new reference."""
        yaw_rad, height_m, rate_m_s = moved
        c, s = math.cos(yaw_rad), math.sin(yaw_rad)
        buffer = self._reference
        buffer[2:13] = (height_m, rate_m_s, c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
        self._last_moved = moved

    def _set_region(self, region: Region | None) -> None:
        """The region's vertices and edge lines (none: the pressure centre is not clamped)."""
        if region is None:
            self._call.region_count = 0
        else:
            count = len(region.vertices)
            rows = np.zeros((count, REGION_ROW))
            rows[:, 0:2] = region.vertices
            if count >= 3:
                rows[:, 2:5] = region.lines
            self._region = rows
            self._call.region = address(rows, np.float64)
            self._call.region_count = count
        self._last_region = region

    def _load_state(self, state: BalanceState,
                    contacts: tuple[ContactConstraint, ContactConstraint]) -> None:
        """Copy the numbers of a state not read in place (not the compiled estimator's)."""
        self._statics.load(state, contacts)
        self._capture[:] = state.capture_point
        self._in[4] = state.omega
        self._com_velocity[:] = state.com_velocity
        self._pelvis_rotation[:] = state.pelvis_rotation
        self._pelvis_angular[:] = state.pelvis_angular_velocity

    @property
    def joints(self) -> int:
        """How many joints the call's torques hold."""
        return len(self._effort_limit)

    @property
    def address(self) -> int:
        """The call's struct, for a call that runs the whole body itself (Walk's legs)."""
        return ctypes.addressof(self._call)

    def set_cop(self, cop: np.ndarray) -> None:
        """The pressure centre atlas_whole_body solves at."""
        self._cop[:] = cop

    def load(self, state: BalanceState, contacts: tuple[ContactConstraint, ContactConstraint],
              joint_positions: np.ndarray, joint_velocities: np.ndarray,
              joint_gains: tuple[np.ndarray, np.ndarray], reference: StandReference,
              moved: MovedReference | None = None) -> None:
        """This tick's input: the state (read in place from a compiled estimate's row, else
        copied), the contacts, the reference (`moved`: its heading, height and rate
        replaced; MOVED_IN_CALL: the caller's call replaces them) and joint gains when they
        changed, the joints (JOINTS_IN_CALL: the compiled estimate's state's, read by the call
        from its scratch data; the state must then be the estimator's last)."""
        row = state.row_address
        self._call.row = row
        if row is None:
            self._load_state(state, contacts)
        else:
            self._statics.load_contacts(contacts)
        if reference is not self._last_reference or (moved is None
                                                     and self._last_moved is not None):
            self._set_reference(reference)
        if moved is MOVED_IN_CALL:
            self._last_moved = moved  # not equal to any heading, height and rate again
        elif moved is not None and moved != self._last_moved:
            self._move_reference(moved)
        if joint_gains is not self._last_gains:
            joints = len(self._effort_limit)
            self._joint_gains[:joints] = joint_gains[0]
            self._joint_gains[joints:] = joint_gains[1]
            self._last_gains = joint_gains
        if joint_positions is JOINTS_IN_CALL:  # the call reads the state's own
            source = _joint_source(state, row)
            if source is not self._gathering:
                self._gather(source)
            return
        if self._gathering is not None:
            self._gather(None)
        self._joints[0] = joint_positions
        self._joints[1] = joint_velocities

    def _gather(self, source: JointSource | None) -> None:
        """Where the call reads the joints: an estimator's scratch qpos and qvel at the joints'
        addresses (its joint_source, kept here: C holds its pointers), or None: from _in."""
        call = self._call
        if source is None:
            call.joint_qpos = call.joint_qvel = call.qpos_adr = call.dof_adr = None
        else:
            qpos, qvel, qpos_adr, dof_adr = source
            call.joint_qpos = address(qpos, np.float64)
            call.joint_qvel = address(qvel, np.float64)
            call.qpos_adr = address(qpos_adr, np.intp)
            call.dof_adr = address(dof_adr, np.intp)
        self._gathering = source

    def _results(self) -> Tick:
        wrenches, torque = self._statics.outputs
        out = self._out.copy()
        return torque.copy(), out[0:2], out[2:5], out[5:8], wrenches.copy()

    def tick(self, state: BalanceState, region: Region | None,
             contacts: tuple[ContactConstraint, ContactConstraint],
             joint_positions: np.ndarray, joint_velocities: np.ndarray,
             joint_gains: tuple[np.ndarray, np.ndarray], reference: StandReference) -> Tick:
        """StandController.tick's numbers: the pressure centre by the capture-point law
        clamped into `region` (None: not clamped), the torques within the effort limits."""
        self.load(state, contacts, joint_positions, joint_velocities, joint_gains, reference)
        if region is not self._last_region:
            self._set_region(region)
        self._library.atlas_stand_tick(self._pointer)
        return self._results()

    def whole_body(self, state: BalanceState, cop: np.ndarray,
                   contacts: tuple[ContactConstraint, ContactConstraint],
                   joint_positions: np.ndarray, joint_velocities: np.ndarray,
                   joint_gains: tuple[np.ndarray, np.ndarray],
                   reference: StandReference, moved: MovedReference | None = None) -> Tick:
        """StandController.whole_body's numbers at the pressure centre `cop`, not clamped
        to the effort limits (`moved`: the reference's heading, height and rate replaced)."""
        self.load(state, contacts, joint_positions, joint_velocities, joint_gains, reference,
                   moved)
        self.set_cop(cop)
        self._library.atlas_whole_body(self._pointer)
        return self._results()
