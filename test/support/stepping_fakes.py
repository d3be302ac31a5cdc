"""The stepping loop without ROS, for the unit tests of the loop, of AtlasCommand and of
the synchronization window: fakes of the publishers, the log and the wall clock, a loop
wired to them, and commands as rospy hands them over."""

from __future__ import annotations

import struct

from tutorial_atlas_control import topics
from tutorial_atlas_control.command.arrays import FIELD_NAMES
from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.msgs.atlas_command import encode_atlas_command
from tutorial_atlas_control.sim.controller_statistics import CommandAgeStatistics
from tutorial_atlas_control.sim.simulator import AtlasSimulator
from tutorial_atlas_control.stepping.loop import LoopSettings, SteppingLoop
from tutorial_atlas_control.stepping.outputs import LoopOutputs
from tutorial_atlas_control.stepping.pacing import Pacer
from tutorial_atlas_control.units import NS_PER_S

#: One outlet per topic the loop publishes; the outlet is the topic's name.
ALL_TOPICS = (topics.CLOCK, topics.JOINT_STATES, topics.IMU, topics.L_FOOT_CONTACT,
              topics.R_FOOT_CONTACT, topics.GROUND_TRUTH_ODOM, topics.TF,
              topics.CONTROLLER_STATISTICS)
LAUNCH_RATES_HZ = {'joint_states': 1000.0, 'odom': 100.0, 'imu': 1000.0, 'contact': 1000.0,
                   'tf': 100.0}


class FakeOutbox:
    """Records what the loop queues and sends; `listeners` are the outlets wanted."""

    def __init__(self, listeners: set[str]) -> None:
        self.listeners = listeners
        self.pending: dict[str, list[bytes]] = {}
        self.sent: dict[str, list[bytes]] = {}
        self.flushes = 0

    def wanted(self, outlet: str) -> bool:
        return outlet in self.listeners

    def add(self, outlet: str, data: bytes | bytearray) -> None:
        self.pending.setdefault(outlet, []).append(bytes(data))

    def replace(self, outlet: str, data: bytes | bytearray) -> None:
        self.pending[outlet] = [bytes(data)]

    def flush(self) -> None:
        for outlet, messages in self.pending.items():
            self.sent.setdefault(outlet, []).extend(messages)
        self.pending = {}
        self.flushes += 1

    def queued(self) -> dict[str, list[bytes]]:
        """Everything the loop queued: sent, then still pending (the loop does not flush
        at shutdown)."""
        return {outlet: self.sent.get(outlet, []) + self.pending.get(outlet, [])
                for outlet in {*self.sent, *self.pending}}


class FakeLog:
    def __init__(self) -> None:
        self.lines: list[tuple[str, str]] = []

    def info(self, text: str) -> None:
        self.lines.append(('info', text))

    def refused_command(self, text: str, _topic: str = '') -> None:
        self.lines.append(('refused', text))

    def kept_fields(self, text: str, _topic: str = '') -> None:
        self.lines.append(('kept', text))

    def warn(self, text: str) -> None:
        self.lines.append(('warn', text))

    def error(self, text: str) -> None:
        self.lines.append(('error', text))

    def fatal(self, text: str) -> None:
        self.lines.append(('fatal', text))

    def of(self, level: str) -> list[str]:
        return [text for kind, text in self.lines if kind == level]


class FakeClock:
    """Wall time that moves only when told to, or when the loop sleeps."""

    def __init__(self) -> None:
        self.now_s = 100.0
        self.slept_s: list[float] = []

    def __call__(self) -> float:
        return self.now_s

    def sleep(self, duration_s: float) -> None:
        self.slept_s.append(duration_s)
        self.now_s += duration_s


def make_loop(sim: AtlasSimulator, listeners: set[str] | None = None,
              rates_hz: dict[str, float] | None = None, paused: bool = False,
              real_time_factor: float = 0.0, balance_stand: bool = False,
              hold_at_start: bool = False) -> tuple[SteppingLoop, FakeOutbox, FakeLog,
                                                    list[str]]:
    outbox = FakeOutbox(set(ALL_TOPICS) if listeners is None else listeners)
    log = FakeLog()
    configs: list[str] = []
    clock = FakeClock()
    outputs = LoopOutputs(outbox, {topic: topic for topic in ALL_TOPICS}, log, configs.append)
    settings = LoopSettings(rates_hz or LAUNCH_RATES_HZ, real_time_factor, paused,
                            balance_stand=balance_stand, hold_at_start=hold_at_start)
    loop = SteppingLoop(sim, outputs, settings, CommandAgeStatistics(sim.dt_s),
                        pacer=Pacer(real_time_factor, clock, clock.sleep))
    return loop, outbox, log, configs


def stops_after(steps: int):
    left = {'turns': steps}

    def is_shutdown() -> bool:
        left['turns'] -= 1
        return left['turns'] < 0
    return is_shutdown


def header_stamp_ns(data: bytes) -> int:
    """The header stamp of a TCPROS-framed message that starts with std_msgs/Header."""
    _, _, secs, nsecs = struct.unpack_from('<IIII', data)
    return secs * NS_PER_S + nsecs


def clock_ns(data: bytes) -> int:
    _, secs, nsecs = struct.unpack_from('<III', data)
    return secs * NS_PER_S + nsecs


def command_bytes(names: list[str], stamp_ns: int = 0, **arrays: list[float]) -> bytes:
    """An osrf_msgs/JointCommands as rospy hands it over (no TCPROS length prefix)."""
    def string(text: str) -> bytes:
        return struct.pack('<I', len(text)) + text.encode()
    secs, nsecs = divmod(stamp_ns, NS_PER_S)
    raw = struct.pack('<III', 0, secs, nsecs) + string('')
    raw += struct.pack('<I', len(names)) + b''.join(string(name) for name in names)
    for field in FIELD_NAMES:
        values = arrays.get(field, [])
        raw += struct.pack(f'<I{len(values)}d', len(values), *values)
    return raw


def complete_command(position_rad: float, stamp_ns: int = 0) -> bytes:
    arrays = {field: [0.0] * NUM_JOINTS for field in FIELD_NAMES}
    arrays['position'] = [position_rad] * NUM_JOINTS
    return command_bytes(list(JOINT_NAMES), stamp_ns, **arrays)


def full(value: float) -> list[float]:
    """One value for every joint."""
    return [value] * NUM_JOINTS


def atlas_bytes(stamp_ns: int = 0, period_ms: int = 0, **arrays: list[float]) -> bytes:
    """An atlas_msgs/AtlasCommand as rospy hands it over."""
    return encode_atlas_command(stamp_ns, arrays, period_ms)
