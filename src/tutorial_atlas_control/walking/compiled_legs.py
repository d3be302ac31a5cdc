"""Walk's single-support tick of the legs as one C call (src/atlas_legs.c through ctypes).

With a foot swinging, LegTasks.torque clamps the pressure centre to the stance sole and
has the whole body solve there, and LegTasks.finish adds the swing leg's servo and clamps
the sum to the effort limits. With the whole-body call and the swing servo compiled, the
Python between them (the clamp, the servo's input copied from the state, the leg's inertia
block, the results' arrays, the sum) cost more than the two calls; here the whole-body
call's input is loaded as it loads it (compiled_whole_body), and one call does the rest,
reading the swing sole's numbers from the compiled estimate's row in place. Used only for a
compiled estimate's state (its row and scratch data); both agree with the pieces and the
Python to rounding (test/unit/walking/test_compiled_legs.py: 1e-9).
"""

from __future__ import annotations

import ctypes
from typing import TYPE_CHECKING

import numpy as np

from tutorial_atlas_control.balance import row_offsets
from tutorial_atlas_control.native import AtlasLegs, AtlasLegsSupport, address
from tutorial_atlas_control.walking.sole_support import NO_SPAN
from tutorial_atlas_control.walking.swing import surface_tilt

if TYPE_CHECKING:
    from tutorial_atlas_control.balance import (
        BalanceState,
        CompiledWholeBody,
        ContactConstraint,
        MovedReference,
        StandReference,
    )
    from tutorial_atlas_control.walking.compiled_swing import CompiledSwing
    from tutorial_atlas_control.walking.footsteps import Footstep
    from tutorial_atlas_control.walking.sole_support import Span
    from tutorial_atlas_control.walking.swing import SwingPath

#: The swing leg's joints.
LEG = 6


class CompiledLegs:
    """atlas_legs_swing_tick over a whole-body call and a swing servo, with the stance sole's
    `reach_m` (along, across) and the legs' first joints; atlas_legs_support_clamp with the
    `region`'s soles' half size (length, width) and margin (m); atlas_legs_support_tick with
    `put_down` (LegGains' press_m, flat_height_m, flat_cos); its buffers its own."""

    def __init__(self, library: ctypes.CDLL, whole_body: CompiledWholeBody,
                 swing: CompiledSwing, reach_m: tuple[float, float],
                 leg_starts: tuple[int, int], region: tuple[float, float, float],
                 put_down: tuple[float, float, float]) -> None:
        self._library = library
        self._whole_body = whole_body
        self._swing = swing
        joints = whole_body.joints
        self._joints = joints
        self._out = np.zeros(joints + 2)
        self._leg_starts = leg_starts
        call = self._call = AtlasLegs()
        call.whole_body = whole_body.address
        call.swing = swing.address
        call.out = address(self._out, np.float64)
        call.reach[:] = reach_m
        call.sole_velocities_at = row_offsets(joints)['sole_velocities']
        call.half_size[0], call.half_size[1], call.margin_m = region
        self._pointer = ctypes.byref(call)
        support = self._support = AtlasLegsSupport()
        support.legs = ctypes.addressof(call)
        support.leg_starts[:] = leg_starts
        self._press_m, support.flat_height_m, support.flat_cos = put_down
        self._support_pointer = ctypes.byref(support)
        #: The poses the support call's feet were set from (none yet).
        self._feet: tuple[Footstep | None, Footstep | None] = (None, None)
        #: The scratch data whose mass matrix was last read (None: not yet), its dofs.
        self._scratch: tuple[int, int] | None = None
        self._mass_matrix = np.zeros(0)
        self._dof_adr: np.ndarray | None = None
        #: The state's mass_matrix_source last seen by load_swing_tick (compared by identity).
        self._source: object = None
        #: The swinging foot the call's leg is set for (None: none yet).
        self._foot: int | None = None
        #: The soles the call's carrying flags say carry (None: not set yet).
        self._carrying: tuple[bool, bool] | None = None

    def _set_foot(self, foot: int) -> None:
        """The swinging foot: its leg's joints and dofs, the other sole the stance."""
        call = self._call
        call.stance = 1 - foot
        start = call.leg_start = self._leg_starts[foot]
        assert self._dof_adr is not None  # bound first
        call.leg_dofs[:] = self._dof_adr[start:start + LEG].tolist()
        self._foot = foot

    def _bind(self, state: BalanceState) -> None:
        """The estimator's model and scratch data the state came from (its mass matrix)."""
        source = state.mass_matrix_source
        assert source is not None  # a compiled estimate's state only
        model, data, nv, dof_adr, mass_current = source
        if self._mass_matrix.size != nv * nv:
            self._mass_matrix = np.zeros(nv * nv)
        call = self._call
        call.model, call.data = model, data
        call.mass_current = mass_current or None  # the step's mass matrix copied: no mj_crb
        call.mass_matrix = address(self._mass_matrix, np.float64)
        self._dof_adr = dof_adr
        for foot, start in enumerate(self._leg_starts):
            self._support.leg_dofs[foot][:] = dof_adr[start:start + LEG].tolist()
        self._scratch = (model, data)
        self._foot = None  # the leg's dofs set again, from these

    def load_swing_tick(self, state: BalanceState,
                        contacts: tuple[ContactConstraint, ContactConstraint],
                        joints: tuple[np.ndarray, np.ndarray],
                        joint_gains: tuple[np.ndarray, np.ndarray], reference: StandReference,
                        moved: MovedReference, swing: tuple[int, SwingPath, float],
                        near: tuple[float, Span] | None = (0.0, NO_SPAN)) -> None:
        """A swinging tick's input but the pressure centre (tick_at sets it, or the walk's
        swing tick, compiled_walk_swing): the state, the stance sole's `contacts`, the joints'
        positions and velocities, their gains, the legs' reference (`moved`: its heading,
        height and rate), `swing` (the foot, its path, the time into it) and `near` (how near
        and the stance sole's bearing box: > 0 across facets, its wrench's pressure centre
        kept within that of the kept one or of the box: sole_support.stance_rule; None: left
        to the walk's swing call, which reads the rule from the row)."""
        source = state.mass_matrix_source
        if source is not self._source or source is None:  # the estimator's one tuple: once
            if source is None or self._scratch != source[0:2]:
                self._bind(state)
            self._source = source
        foot, path, elapsed_s = swing
        if foot != self._foot:
            self._set_foot(foot)
        self._whole_body.load(state, contacts, joints[0], joints[1], joint_gains, reference,
                              moved)
        self._swing.set_path(path)
        self._swing.prepare_swing(elapsed_s)
        if near is not None:
            self._call.near_m = near[0]
            self._call.bearing[:] = near[1]

    def results(self) -> tuple[np.ndarray, np.ndarray]:
        """The last tick's torques (joints,) and pressure centre as kept, new arrays."""
        out = self._out.copy()  # one copy, two views of it
        return out[:self._joints], out[self._joints:]

    def tick_at(self, cop: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """LegTasks.torque then LegTasks.finish on the input load_swing_tick loaded, at the
        pressure centre `cop`: the torques (joints,) within the effort limits and the
        pressure centre as kept, new arrays."""
        self._whole_body.set_cop(cop)
        self._library.atlas_legs_swing_tick(self._pointer)
        return self.results()

    @property
    def address(self) -> int:
        """The call's struct, for a call that runs the tick itself (compiled_walk_swing)."""
        return ctypes.addressof(self._call)

    def _set_carrying(self, carrying: tuple[bool, bool]) -> None:
        """The soles that carry, into the call unless they are there already (a ctypes array's
        slice assignment costs more than the support tick's other input)."""
        if carrying != self._carrying:
            self._call.carrying[:] = carrying
            self._carrying = carrying

    def _set_feet(self, feet: tuple[Footstep, Footstep]) -> None:
        """Each foot's pose for the put-down servo and the flat test (atlas_legs.h's FOOT_*)."""
        for foot, pose in enumerate(feet):
            normal = tuple(pose.normal)
            self._support.feet[foot][:] = (pose.x_m, pose.y_m, pose.z_m - self._press_m,
                                           pose.yaw_rad, *surface_tilt(normal), pose.z_m,
                                           *normal)
        self._feet = (feet[0], feet[1])

    def support_tick(self, state: BalanceState, contacts: tuple[ContactConstraint,
                                                                ContactConstraint],
                     joints: tuple[np.ndarray, np.ndarray],
                     joint_gains: tuple[np.ndarray, np.ndarray], reference: StandReference,
                     moved: MovedReference, cop: np.ndarray, carrying: tuple[bool, bool],
                     feet: tuple[Footstep, Footstep]) -> tuple[np.ndarray, np.ndarray]:
        """LegTasks.torque then LegTasks.finish with no foot swinging: the soles `carrying`
        (their `contacts`), each foot not flat down put back on its pose in `feet`; the
        torques (joints,) within the effort limits and the pressure centre as kept, new
        arrays. A compiled estimate's state only."""
        source = state.mass_matrix_source
        if source is not self._source or source is None:  # as load_swing_tick's
            if source is None or self._scratch != source[0:2]:
                self._bind(state)
            self._source = source
        self._whole_body.load(state, contacts, joints[0], joints[1], joint_gains, reference,
                              moved)
        call = self._call
        call.row = state.row_address
        self._set_carrying(carrying)
        self._out[self._joints:] = cop
        if feet[0] is not self._feet[0] or feet[1] is not self._feet[1]:
            self._set_feet(feet)
        self._library.atlas_legs_support_tick(self._support_pointer)
        self._foot = None  # the call sets the legs' foot for each foot it puts down
        return self.results()

    def support_clamp(self, state: BalanceState, carrying: tuple[bool, bool],
                      cop: np.ndarray) -> np.ndarray:
        """`cop` clamped into the hull of the `carrying` soles shrunk by the margin (the
        Python: clamp_into(convex_hull(their box_corners)), a new array; a compiled
        estimate's state only."""
        call = self._call
        call.row = state.row_address
        self._set_carrying(carrying)
        out = self._out
        out[self._joints:] = cop
        self._library.atlas_legs_support_clamp(self._pointer)
        return out[self._joints:].copy()
