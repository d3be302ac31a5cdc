"""atlas_msgs/AtlasCommand and atlas_msgs/Test: decoding and checking, without genpy.

DRCSim 2.5.2's AtlasPlugin copies each array of exactly 28 entries into the command and
keeps the previous values of any array of another length (SetAtlasCommand,
SetExperimentalDampingPID). We do the same, and say so: an array of another non-zero length
is named in one warning (an empty array is the usual way not to set a field: silent). On top
of DRCSim, a message with NaN/Inf or an absurd magnitude anywhere (arrays.MAX_MAGNITUDE,
MAX_DAMPING) is refused whole, as JointCommands are.

The k_effort bytes become the fraction k_effort / 255 the law blends with (AtlasPlugin's
`static_cast<double>(k_effort) / 255.0`, the same double).
"""

from __future__ import annotations

import struct
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from tutorial_atlas_control.command import (
    ALL_JOINTS,
    K_EFFORT_ROW,
    LAW_FIELDS,
    MAX_MAGNITUDE,
    CommandError,
    CommandUpdate,
    check_values,
)
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.msgs.ros1_fields import FieldCursor
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['ATLAS_COMMAND_FIELDS', 'MAX_DAMPING', 'TEST_FIELDS', 'AtlasCommandDecoder',
           'AtlasUpdate', 'GainMemo', 'decode_atlas_command', 'decode_test', 'encode_atlas_command',
           'encode_test']

_F8, _F4, _U1 = np.dtype('<f8'), np.dtype('<f4'), np.dtype('u1')
#: AtlasCommand's arrays in message order (2.7.0), with their wire types.
ATLAS_COMMAND_FIELDS: tuple[tuple[str, np.dtype], ...] = (
    ('position', _F8), ('velocity', _F8), ('effort', _F8),
    ('kp_position', _F4), ('ki_position', _F4), ('kd_position', _F4), ('kp_velocity', _F4),
    ('k_effort', _U1), ('i_effort_min', _F4), ('i_effort_max', _F4))
#: Test's arrays in message order; `damping` is the joints' viscous damping, not a command.
TEST_FIELDS: tuple[tuple[str, np.dtype], ...] = (
    ('damping', _F4), ('kp_position', _F4), ('ki_position', _F4), ('kd_position', _F4),
    ('kp_velocity', _F4), ('i_effort_min', _F4), ('i_effort_max', _F4), ('k_effort', _U1))
#: Largest joint damping /atlas/debug/test may set (N m s/rad); Atlas v1's joints have 0.1,
#: and beyond this the number is a mistake. Negative damping (energy from nowhere) is refused.
MAX_DAMPING = 1e4
#: k_effort's uint8 full scale: 255 = the PID torque alone.
K_EFFORT_FULL_SCALE = 255.0


@dataclass(frozen=True)
class AtlasUpdate:
    """One checked AtlasCommand or Test message.

    Attributes:
        update: the fields it sets (arrays of exactly 28), ready to merge into a command.
        ignored: (field, length) of each array of another non-zero length, kept as before.
        stamp_ns: its header stamp (ns).
        desired_controller_period_ms: AtlasCommand's (None for Test).
        damping: Test's joint damping (N m s/rad, (28,)), or None when not set.
    """

    update: CommandUpdate
    ignored: tuple[tuple[str, int], ...] = ()
    stamp_ns: int = 0
    desired_controller_period_ms: int | None = None
    damping: np.ndarray | None = None

    def fields_set(self) -> list[str]:
        """The names of the fields it sets, in message order, damping included."""
        names = [LAW_FIELDS[row] for row in self.update.rows]
        return (['damping'] if self.damping is not None else []) + names

    def ignored_text(self) -> str:
        """'' or the warning: which arrays had another length than 28."""
        if not self.ignored:
            return ''
        listed = ', '.join(f'{name} ({length} entries)' for name, length in self.ignored)
        return (f'{listed} not {NUM_JOINTS} long; '
                + ('that field keeps its' if len(self.ignored) == 1 else 'those fields keep their')
                + ' previous values')


def _checked(arrays: Sequence[tuple[str, np.ndarray]], stamp_ns: int,
             period_ms: int | None) -> AtlasUpdate:
    """The fields of 28 entries checked into a CommandUpdate; the others noted as ignored,
    but a NaN or absurd value in any of them refuses the whole message."""
    rows, given, ignored, damping = [], [], [], None
    for name, values in arrays:
        if len(values) == 0:
            continue
        if name == 'damping':
            damping = _checked_damping(values)
            if len(values) != NUM_JOINTS:
                ignored.append((name, len(values)))
                damping = None
            continue
        row = LAW_FIELDS.index(name)
        if len(values) != NUM_JOINTS:
            check_values([row], np.asarray(values, dtype=np.float64)[np.newaxis, :])
            ignored.append((name, len(values)))
            continue
        rows.append(row)
        given.append(values)
    block = np.array(given, dtype=np.float64).reshape(len(rows), NUM_JOINTS)
    check_values(rows, block)
    if K_EFFORT_ROW in rows:
        block[rows.index(K_EFFORT_ROW)] /= K_EFFORT_FULL_SCALE
    return AtlasUpdate(CommandUpdate(ALL_JOINTS, tuple(rows), block), tuple(ignored),
                       stamp_ns, period_ms, damping)


def _checked_damping(values: np.ndarray) -> np.ndarray:
    damping = np.asarray(values, dtype=np.float64)
    for index, value in enumerate(damping):
        if not np.isfinite(value):
            raise CommandError(f'damping[{index}] is {value} (NaN/Inf are refused)')
        if not 0.0 <= value <= MAX_DAMPING:
            raise CommandError(f'damping[{index}] is {value:g}, outside 0..{MAX_DAMPING:g} '
                               'N m s/rad')
    return damping


def _decode(raw: bytes, layout: Sequence[tuple[str, np.dtype]],
            with_period: bool) -> AtlasUpdate:
    try:
        cursor = FieldCursor(raw)
        stamp_ns = cursor.header_stamp_ns()
        arrays = [(name, cursor.array(dtype)) for name, dtype in layout]
        period_ms = cursor.u8() if with_period else None
        if cursor.pos != len(raw):
            raise ValueError(f'{len(raw) - cursor.pos} bytes left after the last field')
    except (ValueError, struct.error, UnicodeDecodeError) as err:
        raise CommandError(f'malformed message ({err})') from None
    return _checked(arrays, stamp_ns, period_ms)


#: A controller's usual AtlasCommand: every array of 28. Its body (after the header) has one
#: layout: read at once, its counts checked by one struct call (the pad bytes skip the data).
_FULL_BODY = np.dtype([item for name, dtype in ATLAS_COMMAND_FIELDS
                       for item in ((f'{name}_count', '<u4'), (name, dtype, (NUM_JOINTS,)))]
                      + [('desired_controller_period_ms', 'u1')])
_FULL_COUNTS = struct.Struct('<' + ''.join(f'I{dtype.itemsize * NUM_JOINTS}x'
                                           for _, dtype in ATLAS_COMMAND_FIELDS))
#: Those counts when every array has 28 entries.
_ALL_FULL = (NUM_JOINTS,) * len(ATLAS_COMMAND_FIELDS)
_FULL_ROWS = tuple(LAW_FIELDS.index(name) for name, _ in ATLAS_COMMAND_FIELDS)
_K_EFFORT_INDEX = _FULL_ROWS.index(K_EFFORT_ROW)


def _full_groups() -> tuple[tuple[int, int, np.dtype, int], ...]:
    """Consecutive arrays of one type in the full body, each read as one strided view:
    (first row, rows, type, offset of the first array's data after the header)."""
    groups: list[list] = []
    offset = 0
    for row, (_, dtype) in enumerate(ATLAS_COMMAND_FIELDS):
        offset += 4  # the array's count
        if groups and groups[-1][2] == dtype:
            groups[-1][1] += 1
        else:
            groups.append([row, 1, dtype, offset])
        offset += dtype.itemsize * NUM_JOINTS
    return tuple((first, count, dtype, start) for first, count, dtype, start in groups)


#: The full body's arrays by group; one array's count and data make each group's row stride.
_FULL_GROUPS = _full_groups()


#: The full body's rows past its float64 group (the gains and k_effort, in message order),
#: the offset of their bytes after the header (from kp_position's count, to before the
#: period's byte), and the float64 group's rows (position, velocity, effort).
_GAIN_ROWS = _FULL_GROUPS[1][0]
_GAINS_FROM = _FULL_GROUPS[1][3] - 4
_TARGET_ROWS = _FULL_ROWS[:_GAIN_ROWS]


def _decode_full(raw: bytes, memo: GainMemo | None = None) -> AtlasUpdate | None:
    """The fast path for an AtlasCommand whose arrays all have 28 entries; None otherwise.

    With `memo`: gains whose bytes equal the last checked ones are taken from it, already
    converted and checked (the same values); only the targets are read and checked.
    """
    try:
        cursor = FieldCursor(raw)
        stamp_ns = cursor.header_stamp_ns()
    except (ValueError, struct.error, UnicodeDecodeError):
        return None
    start = cursor.pos
    if len(raw) - start != _FULL_BODY.itemsize:
        return None
    if _FULL_COUNTS.unpack_from(raw, start) != _ALL_FULL:
        return None
    block = np.empty((len(_FULL_ROWS), NUM_JOINTS))
    gains_from = start + _GAINS_FROM
    known = (memo is not None and bool(memo.gain_bytes)
             and raw.startswith(memo.gain_bytes, gains_from))
    for first, count, dtype, offset in (_FULL_GROUPS[:1] if known else _FULL_GROUPS):
        row_bytes = 4 + dtype.itemsize * NUM_JOINTS
        block[first:first + count] = np.ndarray((count, NUM_JOINTS), dtype, raw, start + offset,
                                                (row_bytes, dtype.itemsize))
    if known:
        assert memo is not None
        check_values(_TARGET_ROWS, block[:_GAIN_ROWS])
        block[_GAIN_ROWS:] = memo.gains
    else:
        check_values(_FULL_ROWS, block)
        block[_K_EFFORT_INDEX] /= K_EFFORT_FULL_SCALE
        if memo is not None:
            memo.gains = block[_GAIN_ROWS:].copy()
            memo.gain_bytes = raw[gains_from:-1]
    # The body's last byte: desired_controller_period_ms (uint8).
    return AtlasUpdate(CommandUpdate(ALL_JOINTS, _FULL_ROWS, block), (), stamp_ns, raw[-1])


class GainMemo:
    """The gains (and k_effort) of the last full AtlasCommand decoded: its bytes, and its
    rows past the targets as checked float64 (k_effort already / 255)."""

    __slots__ = ('gain_bytes', 'gains')

    def __init__(self) -> None:
        self.gain_bytes = b''
        self.gains = np.zeros((len(_FULL_ROWS) - _GAIN_ROWS, NUM_JOINTS))


#: A full AtlasCommand whose header has an empty frame_id (what controllers send): its size,
#: and its header (seq skipped) and counts as one pre-parsed struct: (secs, nsecs, the
#: frame_id's length, the ten counts), which must end in _BARE_FULL.
_HEADER_BYTES = 16
_BARE_SIZE = _HEADER_BYTES + _FULL_BODY.itemsize
_BARE_HEAD = struct.Struct('<4xIII' + _FULL_COUNTS.format[1:])
_BARE_FULL = (0, *_ALL_FULL)
#: Where its gains' bytes start, and its targets' float64 rows (start, stride).
_BARE_GAINS_FROM = _HEADER_BYTES + _GAINS_FROM
_BARE_TARGETS = (_HEADER_BYTES + _FULL_GROUPS[0][3], 4 + _F8.itemsize * NUM_JOINTS)


class AtlasCommandDecoder:
    """decode_atlas_command for one stream of messages.

    A controller sends the same gains in every message and changes only its targets: the
    decoder remembers the last gains' bytes and values (GainMemo), so such a message costs
    the conversion and checks of its three target arrays, not of all ten; with an empty
    frame_id its header and counts are one struct call and its targets' check two ufuncs
    into buffers kept here. Not for concurrent calls (the loop's lock serializes the inbox's).
    """

    def __init__(self) -> None:
        self.memo = GainMemo()
        # check_values' bounds (MAX_MAGNITUDE; the largest float for none): NaN/Inf fail.
        bounds = [min(MAX_MAGNITUDE.get(LAW_FIELDS[row], np.inf), np.finfo(np.float64).max)
                  for row in _TARGET_ROWS]
        self._bounds = np.repeat(np.array(bounds)[:, np.newaxis], NUM_JOINTS, axis=1)
        self._magnitude = np.empty((_GAIN_ROWS, NUM_JOINTS))
        self._within = np.empty((_GAIN_ROWS, NUM_JOINTS), dtype=bool)

    def decode(self, raw: bytes) -> AtlasUpdate:
        """Raises CommandError as decode_atlas_command does."""
        known = self._known_gains(raw)
        if known is not None:
            return known
        full = _decode_full(raw, self.memo)
        if full is not None:
            return full
        return _decode(raw, ATLAS_COMMAND_FIELDS, with_period=True)

    def _known_gains(self, raw: bytes) -> AtlasUpdate | None:
        """A full message with an empty frame_id and the remembered gains; None otherwise
        (the same update _decode_full makes of it, the same refusal)."""
        memo = self.memo
        if len(raw) != _BARE_SIZE or not memo.gain_bytes:
            return None
        head = _BARE_HEAD.unpack_from(raw)
        if head[2:] != _BARE_FULL or not raw.startswith(memo.gain_bytes, _BARE_GAINS_FROM):
            return None
        block = np.empty((len(_FULL_ROWS), NUM_JOINTS))
        targets = block[:_GAIN_ROWS]
        start, stride = _BARE_TARGETS
        targets[:] = np.ndarray((_GAIN_ROWS, NUM_JOINTS), _F8, raw, start, (stride, _F8.itemsize))
        np.abs(targets, out=self._magnitude)
        if not np.less_equal(self._magnitude, self._bounds, out=self._within).all():
            check_values(_TARGET_ROWS, targets)  # raises, naming the first bad entry
        block[_GAIN_ROWS:] = memo.gains
        return AtlasUpdate(CommandUpdate(ALL_JOINTS, _FULL_ROWS, block), (),
                           head[0] * NS_PER_S + head[1], raw[-1])


def decode_atlas_command(raw: bytes) -> AtlasUpdate:
    """A serialized atlas_msgs/AtlasCommand (2.7.0) as an AtlasUpdate.

    Raises:
        CommandError: malformed, or NaN/Inf or an absurd magnitude in any array.
    """
    full = _decode_full(raw)
    if full is not None:
        return full
    return _decode(raw, ATLAS_COMMAND_FIELDS, with_period=True)


def decode_test(raw: bytes) -> AtlasUpdate:
    """A serialized atlas_msgs/Test as an AtlasUpdate (gains, k_effort and damping).

    Raises:
        CommandError: malformed, NaN/Inf, an absurd gain or a damping outside 0..MAX_DAMPING.
    """
    return _decode(raw, TEST_FIELDS, with_period=False)


def _encode(layout: Sequence[tuple[str, np.dtype]], stamp_ns: int,
            arrays: Mapping[str, Sequence[float]], frame_id: str = '') -> bytearray:
    unknown = set(arrays) - {name for name, _ in layout}
    if unknown:
        raise ValueError(f'no such field: {", ".join(sorted(unknown))}')
    secs, nsecs = divmod(stamp_ns, NS_PER_S)
    frame = frame_id.encode()
    out = bytearray(struct.pack('<IIII', 0, secs, nsecs, len(frame)) + frame)
    for name, dtype in layout:
        values = np.asarray(arrays.get(name, ()), dtype=dtype)
        out += struct.pack('<I', len(values)) + values.tobytes()
    return out


def encode_atlas_command(stamp_ns: int, arrays: Mapping[str, Sequence[float]],
                         desired_controller_period_ms: int = 0) -> bytes:
    """A serialized AtlasCommand (without the TCPROS length prefix): for tests and tools.

    `arrays` maps field names to values (k_effort as 0..255); absent fields are empty.
    """
    out = _encode(ATLAS_COMMAND_FIELDS, stamp_ns, arrays)
    return bytes(out + struct.pack('<B', desired_controller_period_ms))


def encode_test(stamp_ns: int, arrays: Mapping[str, Sequence[float]]) -> bytes:
    """A serialized atlas_msgs/Test (without the TCPROS length prefix)."""
    return bytes(_encode(TEST_FIELDS, stamp_ns, arrays))
