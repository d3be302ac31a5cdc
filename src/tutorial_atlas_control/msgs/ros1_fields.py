"""Decoding ROS 1 serialized messages of the form `Header, string[] name, float64[]...`.

sensor_msgs/JointState and osrf_msgs/JointCommands are laid out this way. Reading them
with numpy views instead of genpy's generated deserializer is what lets the bag analysis
read 1 kHz recordings quickly and the simulator take thousands of commands a second.
Pure Python and numpy: no ROS needed.
"""

from __future__ import annotations

import struct

import numpy as np

from tutorial_atlas_control.units import NS_PER_S

_U32 = struct.Struct('<I')


class FieldCursor:
    """Sequential reader of ROS 1 serialized fields (little endian, no alignment).

    Reading past the end raises ValueError (or struct.error); a non-UTF-8 string
    raises UnicodeDecodeError: callers treat all three as a malformed message.
    """

    def __init__(self, data: bytes) -> None:
        self.data = data
        self.pos = 0

    def u32(self) -> int:
        (value,) = _U32.unpack_from(self.data, self.pos)
        self.pos += 4
        return value

    def string(self) -> str:
        length = self.u32()
        end = self.pos + length
        if end > len(self.data):
            raise ValueError(f'a string of {length} bytes runs past the message end')
        self.pos = end
        return self.data[end - length:end].decode()

    def strings(self) -> list[str]:
        count = self.u32()
        if 4 * count > len(self.data) - self.pos:
            raise ValueError(f'{count} strings cannot fit in the message')
        return [self.string() for _ in range(count)]

    def f64s(self) -> np.ndarray:
        """A read-only float64 view of the next float64[] (no copy)."""
        count = self.u32()
        values = np.frombuffer(self.data, dtype='<f8', count=count, offset=self.pos)
        self.pos += 8 * count
        return values

    def array(self, dtype: np.dtype) -> np.ndarray:
        """A read-only view of the next array of little-endian `dtype` (no copy)."""
        count = self.u32()
        values = np.frombuffer(self.data, dtype=dtype, count=count, offset=self.pos)
        self.pos += dtype.itemsize * count
        return values

    def u8(self) -> int:
        if self.pos >= len(self.data):
            raise ValueError('the message ends before its last uint8')
        self.pos += 1
        return self.data[self.pos - 1]

    def header_stamp_ns(self) -> int:
        """Read std_msgs/Header; return its stamp (ns)."""
        self.pos += 4  # seq
        sec, nsec = self.u32(), self.u32()
        self.string()  # frame_id
        return sec * NS_PER_S + nsec


def parse_names_arrays(raw: bytes, arrays: int,
                       whole: bool = False) -> tuple[int, list[str], list[np.ndarray]]:
    """Parse 'Header, string[] name, float64[] x `arrays`' into (stamp ns, names, arrays).

    Args:
        raw: one serialized message (without the TCPROS length prefix).
        arrays: how many float64[] follow the names.
        whole: also require that the message ends right after them.

    Raises:
        ValueError, struct.error, UnicodeDecodeError: the bytes are not such a message.
    """
    cursor = FieldCursor(raw)
    stamp_ns = cursor.header_stamp_ns()
    names = cursor.strings()
    values = [cursor.f64s() for _ in range(arrays)]
    if whole and cursor.pos != len(raw):
        raise ValueError(f'{len(raw) - cursor.pos} bytes left after the last field')
    return stamp_ns, names, values
