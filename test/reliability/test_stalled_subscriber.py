"""A subscriber to /atlas/joint_states that stops reading its socket.

It connects over TCPROS as any node does, then reads nothing. Once the socket buffers are
full, the simulator (node/transport.py) waits for it one STALL_PROBE_S slice, then keeps
what it has not taken in a bounded backlog and goes on; after SEND_TIMEOUT_S without
progress it is dropped with one warning. Checked: that one line, the simulator's memory
(at most the backlog bound over the run's own growth), and the two other subscribers, the
recorder and a live TCPROS reader, losing no step. The real-time factor over the stall and
the longest wait between two messages at the live reader are printed, not asserted
(wall-clock speed is `make bench`'s).
"""

from __future__ import annotations

import socket
import struct
import threading
import time

import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from support.bag_checks import missing_steps
from support.launch import SIM, TestLaunch
from tutorial_atlas_control.bags.reader import JOINT_STATE_MD5, read_bag
from tutorial_atlas_control.node.transport import MAX_BACKLOG_BYTES
from tutorial_atlas_control.processes import node_api, rss_kib

#: Timing or memory claims: run alone, after make test's parallel part.
pytestmark = pytest.mark.serial

STALLED = '/stalled_subscriber'
LIVE = '/live_subscriber'
DROPPED = f'/atlas/joint_states: dropping subscriber {STALLED}: timed out'
#: Wall-clock guard (s): buffers fill in seconds at 1 kHz, then SEND_TIMEOUT_S.
DROP_TIMEOUT_S = 120.0
#: The simulator's growth allowed while stalled (KiB): Python's own churn, plus at most
#: the stalled connection's backlog (MAX_BACKLOG_BYTES, its bound).
MEMORY_SLACK_KIB = 20 * 1024 + MAX_BACKLOG_BYTES // 1024
STEP_NS = 1_000_000


def _field(text: str) -> bytes:
    data = text.encode()
    return struct.pack('<I', len(data)) + data


def joint_states_subscriber(master_uri: str, name: str, rcvbuf: int | None) -> socket.socket:
    """A TCPROS connection to atlas_sim's /atlas/joint_states, its header exchanged."""
    code, message, protocol = node_api(master_uri, SIM, name).requestTopic(
        name, '/atlas/joint_states', [['TCPROS']])
    assert code == 1, message
    _, host, port = protocol
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    if rcvbuf is not None:
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
    sock.connect((host, port))
    header = b''.join(_field(text) for text in (
        f'callerid={name}', 'topic=/atlas/joint_states', f'md5sum={JOINT_STATE_MD5}',
        'type=sensor_msgs/JointState', 'tcp_nodelay=1'))
    sock.sendall(struct.pack('<I', len(header)) + header)
    (length,) = struct.unpack('<I', sock.recv(4, socket.MSG_WAITALL))
    reply = sock.recv(length, socket.MSG_WAITALL)
    assert b'error=' not in reply, reply
    return sock


def stalled_subscriber(master_uri: str) -> socket.socket:
    """A subscriber that will never read (its receive buffer small: fills at once)."""
    return joint_states_subscriber(master_uri, STALLED, 4096)


class LiveReader(threading.Thread):
    """A subscriber that reads everything: each joint state's stamp (ns) and arrival time."""

    def __init__(self, master_uri: str) -> None:
        super().__init__(daemon=True)
        self.sock = joint_states_subscriber(master_uri, LIVE, None)
        self.sock.settimeout(0.5)
        self.stamps_ns: list[int] = []
        self.arrivals_s: list[float] = []
        self.stop = threading.Event()

    def run(self) -> None:
        buffer = bytearray()
        while not self.stop.is_set():
            try:
                chunk = self.sock.recv(1 << 16)
            except TimeoutError:
                continue
            if not chunk:
                return
            now_s = time.monotonic()
            buffer += chunk
            while len(buffer) >= 4:
                (length,) = struct.unpack_from('<I', buffer)
                if len(buffer) < 4 + length:
                    break
                _seq, secs, nsecs = struct.unpack_from('<3I', buffer, 4)  # std_msgs/Header
                self.stamps_ns.append(secs * 1_000_000_000 + nsecs)
                self.arrivals_s.append(now_s)
                del buffer[:4 + length]

    def missing_steps(self) -> int:
        steps = [(b - a + STEP_NS // 2) // STEP_NS
                 for a, b in zip(self.stamps_ns, self.stamps_ns[1:], strict=False)]
        assert all(step >= 1 for step in steps), 'a joint state twice or out of order'
        return sum(step - 1 for step in steps)

    def longest_wait_s(self, since_s: float, until_s: float) -> float:
        """The longest wall time between two arrivals in [since_s, until_s]."""
        times = [t for t in self.arrivals_s if since_s <= t <= until_s]
        return max((b - a for a, b in zip(times, times[1:], strict=False)), default=0.0)


def test_a_stalled_subscriber_is_dropped_and_costs_nobody_a_message(
        atlas_launch: TestLaunch) -> None:
    atlas_launch.wait_ready()
    atlas_launch.wait_sim_s(1.0)
    pid = atlas_launch.pid_of('atlas_sim_node.py')
    live = LiveReader(atlas_launch.uri)
    live.start()
    atlas_launch.wait_sim_s(1.0)
    before_kib = rss_kib(pid)
    peak_kib = [before_kib or 0]

    def dropped() -> bool:
        peak_kib[0] = max(peak_kib[0], rss_kib(pid) or 0)
        return DROPPED in atlas_launch.output()

    sim0_s, wall0_s = atlas_launch.sim_time_s(), time.monotonic()
    sock = stalled_subscriber(atlas_launch.uri)
    try:
        atlas_launch.wait(dropped, DROP_TIMEOUT_S, f'{STALLED} was not dropped')
        sim1_s, wall1_s = atlas_launch.sim_time_s(), time.monotonic()
        after_kib = rss_kib(pid)
        atlas_launch.wait_sim_s(2.0)  # the simulation goes on without it
    finally:
        sock.close()
    atlas_launch.interrupt()
    live.stop.set()
    live.join(5.0)
    live.sock.close()
    dropped_lines = [line for line in atlas_launch.output().splitlines() if STALLED in line]
    assert len(dropped_lines) == 1 and DROPPED in dropped_lines[0], dropped_lines
    assert before_kib is not None and after_kib is not None
    assert peak_kib[0] - before_kib < MEMORY_SLACK_KIB, (before_kib, peak_kib[0])
    assert after_kib - before_kib < MEMORY_SLACK_KIB, (before_kib, after_kib)
    states = read_bag(atlas_launch.bag()).joint_states
    assert states is not None and missing_steps(states) == 0, 'the recorder lost no step'
    assert states.t_s[-1] > sim1_s
    assert live.missing_steps() == 0, 'the live subscriber lost no step'
    assert live.stamps_ns[-1] * 1e-9 > sim1_s
    rtf = (sim1_s - sim0_s) / (wall1_s - wall0_s)
    print(f'figures: stalled subscriber dropped after {wall1_s - wall0_s:.1f} s wall '
          f'({sim1_s - sim0_s:.1f} s sim: real-time factor {rtf:.2f} over the stall); '
          f'live subscriber: longest wait between two joint states over the stall '
          f'{live.longest_wait_s(wall0_s, wall1_s) * 1e3:.0f} ms, {len(live.stamps_ns)} '
          f'joint states, none missing; simulator RSS {before_kib} -> peak {peak_kib[0]} '
          f'-> {after_kib} KiB; recorder: {len(states.t_s)} joint states, none missing')
