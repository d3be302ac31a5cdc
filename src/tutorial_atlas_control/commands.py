"""Validation and merging of osrf_msgs/JointCommands, with DRCSim's semantics made safer.

DRCSim read the arrays by position and ignored `name`. We keep that for an empty
`name` (the tutorial's joint order) and map by name otherwise, with or without the
`atlas::` prefix, in any order, all 28 joints or a subset. A message is applied whole
or not at all: any inconsistency, or an absurd magnitude (MAX_MAGNITUDE), refuses it and
the previous command stays.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from tutorial_atlas_control.controller import FIELD_NAMES, JointCommandArrays
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import JOINT_INDEX, NUM_JOINTS, bare_joint_name


#: Largest magnitude accepted per field; beyond it a value is a mistake, not a command, and
#: the message is refused. The bounds sit far above any working value (DRCSim's largest
#: gains: p 4000, d 20; Atlas v1's velocity limit: 12 rad/s) so they never refuse a real
#: controller. Within them, the law still clamps the position target to the joint limits
#: and the torque to the effort limit. Position has no bound: any finite target is clamped.
MAX_MAGNITUDE: dict[str, float] = {
    'velocity': 1e3,        # rad/s
    'effort': 1e5,          # N m
    'kp_position': 1e6,
    'ki_position': 1e6,
    'kd_position': 1e6,
    'kp_velocity': 1e6,
    'i_effort_min': 1e5,    # N m
    'i_effort_max': 1e5,    # N m
}


class CommandError(AtlasControlError):
    """A JointCommands message that cannot be applied; the text says why."""


def joint_indices(names: Sequence[str]) -> np.ndarray:
    """Map message joint names (bare or `atlas::`-prefixed) to tutorial-order indices.

    An empty `names` means all 28 joints in the tutorial's order, as DRCSim assumed.

    Raises:
        CommandError: a name is unknown or appears twice.
    """
    if not names:
        return np.arange(NUM_JOINTS)
    indices = np.empty(len(names), dtype=np.intp)
    seen: set[int] = set()
    for slot, name in enumerate(names):
        index = JOINT_INDEX.get(bare_joint_name(name))
        if index is None:
            raise CommandError(f'unknown joint name {name!r}')
        if index in seen:
            raise CommandError(f'joint {name!r} is named twice')
        seen.add(index)
        indices[slot] = index
    return indices


def merge_command(previous: JointCommandArrays, names: Sequence[str],
                  arrays: Mapping[str, Sequence[float]]) -> JointCommandArrays:
    """Return `previous` updated with one JointCommands message.

    Args:
        previous: the command in force (not modified).
        names: the message's `name` field.
        arrays: field name -> the message's array, for the fields in FIELD_NAMES.
            An empty array leaves that field as it was.

    Raises:
        CommandError: wrong array length, NaN/Inf, a value beyond MAX_MAGNITUDE,
            unknown or duplicate joint name.
    """
    indices = joint_indices(names)
    expected = len(indices)
    merged = previous.copy()
    for field in FIELD_NAMES:
        values = arrays.get(field, ())
        if len(values) == 0:
            continue
        if len(values) != expected:
            raise CommandError(
                f'{field} has {len(values)} entries for {expected} commanded joints')
        vector = np.asarray(values, dtype=np.float64)
        if not np.all(np.isfinite(vector)):
            bad = int(np.flatnonzero(~np.isfinite(vector))[0])
            raise CommandError(f'{field}[{bad}] is {vector[bad]} (NaN/Inf are refused)')
        bound = MAX_MAGNITUDE.get(field)
        if bound is not None and np.any(np.abs(vector) > bound):
            bad = int(np.flatnonzero(np.abs(vector) > bound)[0])
            raise CommandError(f'{field}[{bad}] is {vector[bad]:g}, beyond the sane bound '
                               f'of {bound:g} in magnitude')
        getattr(merged, field)[indices] = vector
    return merged

