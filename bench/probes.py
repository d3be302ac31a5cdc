"""Light ROS probes in the benchmark process: raw (AnyMsg) subscribers that only timestamp.

The callbacks store (perf_counter, raw bytes) and return; parsing happens after the
measurement window, so the probes cost the machine as little as a subscriber can.
rospy runs each subscription's callbacks in that connection's receive thread, so the
timestamp is taken right after the message has been read off the socket.
"""

from __future__ import annotations

import struct
import threading
import time

import rospy

_U32 = struct.Struct('<I')
_CLOCK = struct.Struct('<II')
_HEADER = struct.Struct('<III')


class RawRecorder:
    """Subscribes to `topic` with rospy.AnyMsg; keeps arrivals while recording."""

    def __init__(self, topic: str) -> None:
        self.topic = topic
        self.lock = threading.Lock()
        self.count = 0          # every message ever received (readiness checks)
        self.recording = False
        self.samples: list[tuple[float, bytes]] = []
        self.subscriber = rospy.Subscriber(topic, rospy.AnyMsg, self._on_message,
                                           queue_size=None, tcp_nodelay=True)

    def _on_message(self, msg: rospy.AnyMsg) -> None:
        now = time.perf_counter()
        self.count += 1
        if self.recording:
            self.samples.append((now, msg._buff))

    def start(self) -> None:
        with self.lock:
            self.samples = []
            self.recording = True

    def recorded(self) -> int:
        """How many messages the recording holds so far."""
        return len(self.samples)

    def stop(self) -> list[tuple[float, bytes]]:
        with self.lock:
            self.recording = False
            samples, self.samples = self.samples, []
        return samples


def clock_ns(raw: bytes) -> int:
    """rosgraph_msgs/Clock wire bytes -> sim time (ns)."""
    secs, nsecs = _CLOCK.unpack_from(raw, 0)
    return secs * 1_000_000_000 + nsecs


def header_stamp_ns(raw: bytes) -> int:
    """Stamp (ns) of a message that starts with std_msgs/Header."""
    _, secs, nsecs = _HEADER.unpack_from(raw, 0)
    return secs * 1_000_000_000 + nsecs


def joint_state_effort(raw: bytes, joint: str) -> float | None:
    """effort[joint] of a sensor_msgs/JointState in wire bytes (None if absent)."""
    offset = _HEADER.size
    (length,) = _U32.unpack_from(raw, offset)
    offset += 4 + length                           # frame_id
    (count,) = _U32.unpack_from(raw, offset)
    offset += 4
    index = None
    target = joint.encode()
    for slot in range(count):
        (length,) = _U32.unpack_from(raw, offset)
        if raw[offset + 4:offset + 4 + length] == target:
            index = slot
        offset += 4 + length
    for _ in range(2):                             # position, velocity
        (length,) = _U32.unpack_from(raw, offset)
        offset += 4 + 8 * length
    (length,) = _U32.unpack_from(raw, offset)
    if index is None or index >= length:
        return None
    return struct.unpack_from('<d', raw, offset + 4 + 8 * index)[0]
