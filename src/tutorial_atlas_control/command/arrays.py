"""The command the law reads: osrf_msgs/JointCommands' arrays as numpy, checked and merged.

Below msgs/ (whose decoders produce it: joint_commands.py, atlas_command.py) and sim/
(whose law reads it), so neither imports the other for it.

DRCSim read the arrays by position and ignored `name`. We keep that for an empty
`name` (the tutorial's joint order) and map by name otherwise, with or without the
`atlas::` prefix, in any order, all 28 joints or a subset. A message is applied whole
or not at all: any inconsistency, or an absurd magnitude (MAX_MAGNITUDE), refuses it and
the previous command stays.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, fields

import numpy as np

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import NUM_JOINTS, joint_index

#: The array fields of osrf_msgs/JointCommands, in message order.
FIELD_NAMES: tuple[str, ...] = (
    'position', 'velocity', 'effort', 'kp_position', 'ki_position', 'kd_position',
    'kp_velocity', 'i_effort_min', 'i_effort_max',
)
#: What the law reads per joint: JointCommands' fields and atlas_msgs/AtlasCommand's
#: k_effort (as the fraction k_effort/255 the law blends with).
LAW_FIELDS: tuple[str, ...] = FIELD_NAMES + ('k_effort',)
K_EFFORT_ROW = LAW_FIELDS.index('k_effort')


def _zeros() -> np.ndarray:
    return np.zeros(NUM_JOINTS)


def _ones() -> np.ndarray:
    return np.ones(NUM_JOINTS)


@dataclass
class JointCommandArrays:
    """One JointCommands message as float64 (28,) arrays in the tutorial's joint order.

    Units: position rad, velocity rad/s, effort N m; kp_position N m/rad,
    ki_position N m/(rad s), kd_position N m s/rad, kp_velocity N m s/rad;
    i_effort_min/max N m (bounds of the integral term's torque); k_effort: the share of
    this command's PID torque in the joint's torque (AtlasCommand's uint8 / 255; the rest
    is the behaviour's torque, see controller.compute_torque). 1 unless an AtlasCommand,
    /atlas/debug/test or a mode switch set it.
    """

    position: np.ndarray = field(default_factory=_zeros)
    velocity: np.ndarray = field(default_factory=_zeros)
    effort: np.ndarray = field(default_factory=_zeros)
    kp_position: np.ndarray = field(default_factory=_zeros)
    ki_position: np.ndarray = field(default_factory=_zeros)
    kd_position: np.ndarray = field(default_factory=_zeros)
    kp_velocity: np.ndarray = field(default_factory=_zeros)
    i_effort_min: np.ndarray = field(default_factory=_zeros)
    i_effort_max: np.ndarray = field(default_factory=_zeros)
    k_effort: np.ndarray = field(default_factory=_ones)

    @classmethod
    def zeros(cls) -> JointCommandArrays:
        """All fields 0 (k_effort 1): no target gains, no feed-forward, a limp robot."""
        return cls()

    def copy(self) -> JointCommandArrays:
        """Deep copy (the arrays are copied, so the copy can be handed to another thread).

        The copy's arrays are the rows of one (fields, joints) block, in LAW_FIELDS order:
        the compiled law binds a new command by one address instead of ten (rows_block).
        """
        source = self.rows_block()
        if source is not None:
            return JointCommandArrays.from_block(source.copy())  # one copy, not ten
        block = np.empty((len(LAW_FIELDS), NUM_JOINTS))
        for row, name in enumerate(LAW_FIELDS):
            block[row] = getattr(self, name)
        return JointCommandArrays.from_block(block)

    @classmethod
    def from_block(cls, block: np.ndarray) -> JointCommandArrays:
        """The command whose arrays are the rows of `block` ((fields, joints) float64, in
        LAW_FIELDS order; not copied): what rows_block() then returns."""
        command = cls(*block)
        command._block = block
        return command

    def rows_block(self) -> np.ndarray | None:
        """The float64 block whose rows, in LAW_FIELDS order, are this command's arrays (a
        copy() has one), or None: without one, or once a field was given another array."""
        block = self.__dict__.get('_block')
        if block is None:
            return None
        # Spelled out, not a loop over LAW_FIELDS: the node asks several times a step.
        if (self.position.base is block and self.velocity.base is block
                and self.effort.base is block and self.kp_position.base is block
                and self.ki_position.base is block and self.kd_position.base is block
                and self.kp_velocity.base is block and self.i_effort_min.base is block
                and self.i_effort_max.base is block and self.k_effort.base is block):
            return block
        return None


assert tuple(f.name for f in fields(JointCommandArrays)) == LAW_FIELDS


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


#: MAX_MAGNITUDE per field in LAW_FIELDS order (inf: no bound).
_BOUNDS = np.array([MAX_MAGNITUDE.get(name, np.inf) for name in LAW_FIELDS])
ALL_JOINTS = np.arange(NUM_JOINTS)
ALL_JOINTS.setflags(write=False)


def joint_indices(names: Sequence[str]) -> np.ndarray:
    """Map message joint names (bare or `atlas::`-prefixed) to tutorial-order indices.

    An empty `names` means all 28 joints in the tutorial's order, as DRCSim assumed.
    Controllers send the same list at every message: the mapping is cached per list.

    Raises:
        CommandError: a name is unknown or appears twice.
    """
    if not names:
        return ALL_JOINTS
    return _indices_of(tuple(names))


@functools.lru_cache(maxsize=64)
def _distinct_rows(rows: tuple[int, ...]) -> np.ndarray | None:
    """`rows` as an index array when no row repeats (one assignment writes them all, as
    one per row would), else None: a repeated row's last values win row by row."""
    if len(set(rows)) != len(rows):
        return None
    return np.array(rows, dtype=np.intp)


@functools.lru_cache(maxsize=64)
def _indices_of(names: tuple[str, ...]) -> np.ndarray:
    indices = np.empty(len(names), dtype=np.intp)
    seen: set[int] = set()
    for slot, name in enumerate(names):
        index = joint_index(name)
        if index is None:
            raise CommandError(f'unknown joint name {name!r}')
        if index in seen:
            raise CommandError(f'joint {name!r} is named twice')
        seen.add(index)
        indices[slot] = index
    if np.array_equal(indices, ALL_JOINTS):
        return ALL_JOINTS  # the tutorial's order: CommandUpdate.apply_to's whole rows
    indices.setflags(write=False)  # shared by every message with these names
    return indices


@dataclass(frozen=True)
class CommandUpdate:
    """One checked command message: what it sets, ready to apply to any command.

    `values[k]` holds field LAW_FIELDS[rows[k]] for the joints `indices`; every value is
    finite and within MAX_MAGNITUDE.
    """

    indices: np.ndarray
    rows: tuple[int, ...]
    values: np.ndarray

    @property
    def all_joints(self) -> bool:
        """Sets its fields for every joint: an older message's values of them do not
        survive it."""
        return len(self.indices) == NUM_JOINTS

    @property
    def is_complete(self) -> bool:
        """Sets every field of every joint: nothing of an earlier command survives it."""
        return len(set(self.rows)) == len(LAW_FIELDS) and self.all_joints

    def apply_to(self, command: JointCommandArrays) -> None:
        """Write this update into `command` (in place).

        A controller's update sets whole rows of every joint in order: written into the
        command's block by one assignment instead of one per field (the same values).
        """
        block = command.rows_block() if self.indices is ALL_JOINTS else None
        rows = _distinct_rows(self.rows) if block is not None else None
        if rows is not None:
            block[rows] = self.values
            return
        for row, values in zip(self.rows, self.values):
            getattr(command, LAW_FIELDS[row])[self.indices] = values


def command_update(names: Sequence[str],
                   arrays: Mapping[str, Sequence[float]]) -> CommandUpdate:
    """Check one message's name and array fields; empty arrays leave their field alone.

    Raises:
        CommandError: wrong array length, NaN/Inf, a value beyond MAX_MAGNITUDE,
            unknown or duplicate joint name.
    """
    return checked_update(joint_indices(names), [arrays.get(name, ()) for name in FIELD_NAMES])


def checked_update(indices: np.ndarray, fields: Sequence[Sequence[float]]) -> CommandUpdate:
    """command_update for joints already mapped to `indices`, fields in FIELD_NAMES order."""
    expected = len(indices)
    rows, given = [], []
    for row, values in enumerate(fields):
        if len(values) == 0:
            continue
        if len(values) != expected:
            raise CommandError(f'{FIELD_NAMES[row]} has {len(values)} entries for {expected} '
                               'commanded joints')
        rows.append(row)
        given.append(values)
    # One (fields, joints) block: the checks below are a few numpy calls, not 9 x 3.
    block = np.array(given, dtype=np.float64).reshape(len(rows), expected)
    check_values(rows, block)
    return CommandUpdate(indices, tuple(rows), block)


def check_values(rows: Sequence[int], block: np.ndarray) -> None:
    """Refuse NaN/Inf and magnitudes beyond MAX_MAGNITUDE in a (fields, joints) block whose
    row k holds field LAW_FIELDS[rows[k]].

    Raises:
        CommandError: naming the first bad entry, in message order.
    """
    if (np.abs(block) <= _finite_bounds(tuple(rows))).all():
        return  # the usual case, in two array operations: NaN and Inf compare False
    bad = ~np.isfinite(block)
    if bad.any():
        row, column = np.argwhere(bad)[0]
        raise CommandError(f'{LAW_FIELDS[rows[row]]}[{column}] is {block[row, column]} '
                           '(NaN/Inf are refused)')
    bounds = _BOUNDS[list(rows)]
    beyond = np.abs(block) > bounds[:, np.newaxis]
    if beyond.any():
        row, column = np.argwhere(beyond)[0]
        raise CommandError(f'{LAW_FIELDS[rows[row]]}[{column}] is {block[row, column]:g}, '
                           f'beyond the sane bound of {bounds[row]:g} in magnitude')


@functools.lru_cache(maxsize=64)
def _finite_bounds(rows: tuple[int, ...]) -> np.ndarray:
    """MAX_MAGNITUDE of each row as a column, the largest float for no bound: a value within
    it is finite and sane (check_values' quick test)."""
    column = np.minimum(_BOUNDS[list(rows)], np.finfo(np.float64).max)[:, np.newaxis]
    column.setflags(write=False)
    return column


def merge_command(previous: JointCommandArrays, names: Sequence[str],
                  arrays: Mapping[str, Sequence[float]]) -> JointCommandArrays:
    """Return `previous` updated with one JointCommands message (`previous` is unchanged).

    Args:
        previous: the command in force.
        names: the message's `name` field.
        arrays: field name -> the message's array, for the fields in FIELD_NAMES.
            An empty array leaves that field as it was.

    Raises:
        CommandError: as command_update.
    """
    update = command_update(names, arrays)
    merged = previous.copy()
    update.apply_to(merged)
    return merged
