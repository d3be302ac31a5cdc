"""atlas_msgs/AtlasSimInterfaceCommand (DRCSim 2.6/2.7): decoding and checking, without genpy.

DRCSim's AtlasPlugin takes every message's behaviour and parameter blocks, and its
k_effort only at exactly 28 entries (else the previous blend stays). On top of DRCSim,
a message with NaN/Inf or an absurd magnitude in any float is refused whole, with one line
naming the field, before anything reaches the behaviours. An unknown behaviour number is
not refused here: the behaviours report it (error_code, FAILED_TRANS_UNKNOWN_BEHAVIOR),
as the library did.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass

import numpy as np

from tutorial_atlas_control.command import CommandError
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.msgs.ros1_fields import FieldCursor
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['BEHAVIORS', 'MAX_ABS_VALUE', 'STEP_QUEUE_LENGTH', 'AsiCommand', 'ManipulateParams',
           'StepData', 'decode_asi_command', 'encode_asi_command', 'step_data_bytes']

#: AtlasSimInterfaceCommand's behaviour constants, by value.
BEHAVIORS: dict[int, str] = {0: 'STAND', 1: 'USER', 2: 'FREEZE', 3: 'STAND_PREP', 4: 'WALK',
                             5: 'STEP', 6: 'MANIPULATE'}
WALK, STEP = 4, 5
#: walk_params.step_queue's fixed length.
STEP_QUEUE_LENGTH = 4
#: Larger floats (m, s, rad) are refused as absurd: no step or pelvis target is that far.
MAX_ABS_VALUE = 1e4
#: k_effort's uint8 full scale: 255 = the user's PID alone.
K_EFFORT_FULL_SCALE = 255.0

_STEP = struct.Struct('<II9d')      # step_index, foot_index, duration, pose (7), swing_height
_STEP_FLOATS = ('duration', 'pose.position.x', 'pose.position.y', 'pose.position.z',
                'pose.orientation.x', 'pose.orientation.y', 'pose.orientation.z',
                'pose.orientation.w', 'swing_height')
_MANIPULATE = struct.Struct('<?3d?')
_MANIPULATE_FLOATS = ('desired.pelvis_height', 'desired.pelvis_yaw', 'desired.pelvis_lat')
_I32 = struct.Struct('<i')
_BOOL = struct.Struct('<?')


@dataclass(frozen=True)
class StepData:
    """atlas_msgs/AtlasBehaviorStepData: foot_index 0 left, 1 right."""

    step_index: int = 0
    foot_index: int = 0
    duration_s: float = 0.0
    position_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    orientation_xyzw: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    swing_height_m: float = 0.0

    def yaw_rad(self) -> float:
        """The pose's yaw; an all-zero quaternion (a default message) reads as yaw 0."""
        x, y, z, w = self.orientation_xyzw
        return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


@dataclass(frozen=True)
class ManipulateParams:
    """atlas_msgs/AtlasBehaviorManipulateParams."""

    use_desired: bool = False
    pelvis_height_m: float = 0.0
    pelvis_yaw_rad: float = 0.0
    pelvis_lat_m: float = 0.0
    use_demo_mode: bool = False


@dataclass(frozen=True)
class AsiCommand:
    """One checked AtlasSimInterfaceCommand.

    Attributes:
        behavior: the requested behaviour number (BEHAVIORS; others are the behaviours' to
            report as unknown).
        k_effort: the blend fractions k_effort / 255 ((28,)), or None when the message had
            another length (the previous blend stays).
        k_effort_length: how many k_effort entries the message had.
    """

    stamp_ns: int
    behavior: int
    step_queue: tuple[StepData, ...]
    use_demo_walk: bool
    desired_step: StepData
    step_use_demo_walk: bool
    manipulate: ManipulateParams
    k_effort: np.ndarray | None
    k_effort_length: int

    def ignored_text(self) -> str:
        """'' or the warning for a k_effort of another non-zero length than 28."""
        if self.k_effort_length in (0, NUM_JOINTS):
            return ''
        return (f'k_effort ({self.k_effort_length} entries) not {NUM_JOINTS} long; '
                'the previous blend stays')


def _checked(values: tuple[float, ...], names: tuple[str, ...], prefix: str) -> None:
    for name, value in zip(names, values):
        if not math.isfinite(value):
            raise CommandError(f'{prefix}{name} is {value} (NaN/Inf are refused)')
        if abs(value) > MAX_ABS_VALUE:
            raise CommandError(f'{prefix}{name} is {value:g}, beyond ±{MAX_ABS_VALUE:g}')


def _read_step(cursor: FieldCursor, prefix: str) -> StepData:
    fields = _STEP.unpack_from(cursor.data, cursor.pos)
    cursor.pos += _STEP.size
    _checked(fields[2:], _STEP_FLOATS, prefix)
    return StepData(fields[0], fields[1], fields[2], tuple(fields[3:6]), tuple(fields[6:10]),
                    fields[10])


def _check_foot(step: StepData, prefix: str) -> None:
    """A step the behaviour will take (step_index > 0: 0 marks an unused slot) names a foot."""
    if step.step_index > 0 and step.foot_index not in (0, 1):
        raise CommandError(f'{prefix}foot_index is {step.foot_index}, not 0 (left) or '
                           '1 (right)')


def _read_bool(cursor: FieldCursor) -> bool:
    (value,) = _BOOL.unpack_from(cursor.data, cursor.pos)
    cursor.pos += 1
    return value


def _read(raw: bytes) -> AsiCommand:
    cursor = FieldCursor(raw)
    stamp_ns = cursor.header_stamp_ns()
    (behavior,) = _I32.unpack_from(raw, cursor.pos)
    cursor.pos += 4
    queue = tuple(_read_step(cursor, f'walk_params.step_queue[{i}].')
                  for i in range(STEP_QUEUE_LENGTH))
    use_demo_walk = _read_bool(cursor)
    step = _read_step(cursor, 'step_params.desired_step.')
    step_demo = _read_bool(cursor)
    cursor.pos += 4  # stand_params.placeholder
    manipulate = _MANIPULATE.unpack_from(raw, cursor.pos)
    cursor.pos += _MANIPULATE.size
    _checked(manipulate[1:4], _MANIPULATE_FLOATS, 'manipulate_params.')
    k_effort = cursor.array(np.dtype('u1'))
    if cursor.pos != len(raw):
        raise ValueError(f'{len(raw) - cursor.pos} bytes left after the last field')
    if behavior == WALK:
        for i, queued in enumerate(queue):
            _check_foot(queued, f'walk_params.step_queue[{i}].')
            if queued.step_index > 0 and not queued.duration_s > 0.0:
                raise CommandError(f'walk_params.step_queue[{i}].duration is '
                                   f'{queued.duration_s:g}, not positive')
    elif behavior == STEP:
        _check_foot(step, 'step_params.desired_step.')
    fractions = (k_effort / K_EFFORT_FULL_SCALE if len(k_effort) == NUM_JOINTS else None)
    return AsiCommand(stamp_ns, behavior, queue, use_demo_walk, step, step_demo,
                      ManipulateParams(*manipulate), fractions, len(k_effort))


def decode_asi_command(raw: bytes) -> AsiCommand:
    """A serialized atlas_msgs/AtlasSimInterfaceCommand as an AsiCommand.

    Raises:
        CommandError: malformed, or NaN/Inf or an absurd magnitude in any float field.
    """
    try:
        return _read(raw)
    except (ValueError, struct.error, UnicodeDecodeError) as err:
        raise CommandError(f'malformed AtlasSimInterfaceCommand ({err})') from None


def step_data_bytes(step: StepData) -> bytes:
    """An atlas_msgs/AtlasBehaviorStepData's wire bytes (the command's and the state's)."""
    return _STEP.pack(step.step_index, step.foot_index, step.duration_s, *step.position_m,
                      *step.orientation_xyzw, step.swing_height_m)


def encode_asi_command(command: AsiCommand, k_effort_bytes: bytes = b'',
                       frame_id: str = '') -> bytes:
    """The wire bytes of `command` (k_effort given as its raw bytes): for tests, and for
    clients that pre-serialize."""
    secs, nsecs = divmod(command.stamp_ns, NS_PER_S)
    frame = frame_id.encode()
    out = bytearray(struct.pack('<III', 0, secs, nsecs) + struct.pack('<I', len(frame)) + frame)
    out += _I32.pack(command.behavior)
    for step in command.step_queue:
        out += step_data_bytes(step)
    out += _BOOL.pack(command.use_demo_walk)
    out += step_data_bytes(command.desired_step) + _BOOL.pack(command.step_use_demo_walk)
    out += _I32.pack(0)
    m = command.manipulate
    out += _MANIPULATE.pack(m.use_desired, m.pelvis_height_m, m.pelvis_yaw_rad, m.pelvis_lat_m,
                            m.use_demo_mode)
    out += struct.pack('<I', len(k_effort_bytes)) + k_effort_bytes
    return bytes(out)
