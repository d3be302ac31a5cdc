"""osrf_msgs/JointCommands decoded from its serialized bytes into a checked CommandUpdate.

The decoding is the wire format's (msgs/); what the arrays mean, their checks and their
merging are the command model's (command/arrays.py), which the law reads.
"""

from __future__ import annotations

import struct

import numpy as np

from tutorial_atlas_control.command import (
    ALL_JOINTS,
    FIELD_NAMES,
    CommandError,
    CommandUpdate,
    checked_update,
    joint_indices,
)
from tutorial_atlas_control.msgs.ros1_fields import FieldCursor

__all__ = ['CommandDecoder']


class CommandDecoder:
    """Serialized osrf_msgs/JointCommands -> CommandUpdate, without genpy.

    A controller sends the same joint names in every message: the decoder remembers the
    last serialized `name` block and its joint indices, so a message with the same block
    costs one bytes comparison instead of decoding and looking up 28 strings. Safe to
    share between rospy's receiving threads (the memo is replaced as one tuple).
    """

    def __init__(self) -> None:
        self._memo: tuple[bytes, np.ndarray] = (b'', ALL_JOINTS)

    def decode(self, raw: bytes) -> CommandUpdate:
        """Raises CommandError: a malformed message, or one command_update refuses."""
        try:
            cursor = FieldCursor(raw)
            cursor.header_stamp_ns()
            start = cursor.pos
            names_block, indices = self._memo
            if names_block and raw.startswith(names_block, start):
                cursor.pos = start + len(names_block)
            else:
                indices = joint_indices(cursor.strings())
                self._memo = (raw[start:cursor.pos], indices)
            fields = [cursor.f64s() for _ in FIELD_NAMES]
            if cursor.pos != len(raw):
                raise ValueError(f'{len(raw) - cursor.pos} bytes left after the last field')
        except (ValueError, struct.error, UnicodeDecodeError) as err:
            raise CommandError(f'malformed message ({err})') from None
        return checked_update(indices, fields)
