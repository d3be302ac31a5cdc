"""The whole-body layer's inverse statics as one C call (src/atlas_statics.c through ctypes).

WholeBodyLayer.solve's default solver shares the tasks' wrench between the soles
(contact_wrench.split_wrench), makes each share feasible (make_feasible) and turns the
shares into torques (bias - J^T w): some fifty small float and numpy operations a tick in
Python, one call here. The state's numbers are copied into one input array whose address C
keeps; the soles' constraints are written only when they change. The library is found by
tutorial_atlas_control.native; the layer falls back to Python after one warning without it.
Both agree to rounding (test/unit/balance/test_compiled_statics.py: 1e-9).
"""

from __future__ import annotations

import ctypes
import math
from typing import TYPE_CHECKING

import numpy as np

from tutorial_atlas_control.balance.contact_wrench import MIN_LOAD_SHARE
from tutorial_atlas_control.native import AtlasStatics, address

if TYPE_CHECKING:
    from tutorial_atlas_control.balance.estimator import BalanceState
    from tutorial_atlas_control.balance.whole_body import ContactConstraint

#: A sole's constraint as C reads it: carries, half length, half width, torsion, friction,
#: the centre of its pressure centre's region (along, across).
FOOT = 7
#: The input's fixed part (src/atlas_statics.c's enum): force, moment, com, sole centres
#: (2, 3), sole rotations (2, 3, 3).
FIXED_SIZE = 33


class CompiledStatics:
    """atlas_inverse_statics for `joints` joints, its buffers its own."""

    def __init__(self, library: ctypes.CDLL, joints: int) -> None:
        self._library = library
        self._in = np.zeros(FIXED_SIZE + 13 * joints)
        self._feet = np.zeros((2, FOOT))
        self._wrenches = np.zeros((2, 6))
        self._torque = np.zeros(joints)
        buffer = self._in
        self._force, self._moment, self._com = buffer[0:3], buffer[3:6], buffer[6:9]
        self._centres = buffer[9:15].reshape(2, 3)
        self._rotations = buffer[15:33].reshape(2, 3, 3)
        self._bias = buffer[33:33 + joints]
        self._jacobians = buffer[33 + joints:].reshape(2, 6, joints)
        self._contacts: tuple[ContactConstraint, ContactConstraint] | None = None
        call = self._call = AtlasStatics()
        call.in_ = address(self._in, np.float64)
        call.feet = address(self._feet, np.float64)
        call.wrenches = address(self._wrenches, np.float64)
        call.torque = address(self._torque, np.float64)
        call.min_load_share = MIN_LOAD_SHARE
        call.n = joints
        self._pointer = ctypes.byref(call)

    def _set_contacts(self, contacts: tuple[ContactConstraint, ContactConstraint]) -> None:
        for foot, contact in enumerate(contacts):
            self._feet[foot] = (
                float(contact.carries), contact.half_length_m, contact.half_width_m,
                math.nan if contact.torsion_m is None else contact.torsion_m,
                math.nan if contact.friction is None else contact.friction,
                *contact.centre_m)
        self._contacts = contacts

    @property
    def address(self) -> int:
        """The address of its AtlasStatics, for a call that fills the force and moment and
        calls atlas_inverse_statics itself (compiled_whole_body)."""
        return ctypes.addressof(self._call)

    @property
    def outputs(self) -> tuple[np.ndarray, np.ndarray]:
        """Its output buffers (wrenches (2, 6), torque (n,)), rewritten by each call."""
        return self._wrenches, self._torque

    def load_contacts(self, contacts: tuple[ContactConstraint, ContactConstraint]) -> None:
        """Write `contacts` when they are other objects than last call's."""
        last = self._contacts
        if last is None or last[0] is not contacts[0] or last[1] is not contacts[1]:
            self._set_contacts(contacts)

    def load(self, state: BalanceState,
             contacts: tuple[ContactConstraint, ContactConstraint]) -> None:
        """Copy the numbers of `state` the statics reads, and `contacts` when they changed."""
        self.load_contacts(contacts)
        self._com[:] = state.com
        self._centres[:] = state.sole_centres
        self._rotations[:] = state.sole_rotations
        self._bias[:] = state.bias_nm
        self._jacobians[:] = state.sole_jacobians

    def solve(self, force: np.ndarray, moment: np.ndarray, state: BalanceState,
              contacts: tuple[ContactConstraint, ContactConstraint],
              ) -> tuple[np.ndarray, np.ndarray]:
        """(wrenches (2, 6), torque (n,)), new arrays: `force`, `moment` about the centre of
        mass shared between the carrying soles of `contacts`, each share feasible, and
        bias - J^T w at `state`."""
        self.load(state, contacts)
        self._force[:] = force
        self._moment[:] = moment
        self._library.atlas_inverse_statics(self._pointer)
        return self._wrenches.copy(), self._torque.copy()
