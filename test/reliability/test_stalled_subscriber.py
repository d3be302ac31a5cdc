"""A subscriber to /atlas/joint_states that stops reading its socket (issue 29).

It connects over TCPROS as any node does, then reads nothing. The simulator's sends are
synchronous (node/transport.py): once the socket buffers are full, a send waits up to
SEND_TIMEOUT_S, then the subscriber is dropped with one warning. Checked: that one line,
the simulator's memory (nothing queued for the stalled subscriber), and the recorder (the
other subscriber) losing no step. The real-time factor during the stall is printed, not
asserted (wall-clock speed is `make bench`'s).
"""

from __future__ import annotations

import socket
import struct
import time
import xmlrpc.client

import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from support.bag_checks import missing_steps
from support.launch import TestLaunch
from tutorial_atlas_control.bags.reader import JOINT_STATE_MD5, read_bag
from tutorial_atlas_control.processes import rss_kib

STALLED = '/stalled_subscriber'
DROPPED = f'/atlas/joint_states: dropping subscriber {STALLED}: timed out'
#: Wall-clock guard (s): buffers fill in seconds at 1 kHz, then SEND_TIMEOUT_S.
DROP_TIMEOUT_S = 120.0
#: The simulator's growth allowed while stalled (KiB): Python's own churn, no queue.
MEMORY_SLACK_KIB = 20 * 1024


def _field(text: str) -> bytes:
    data = text.encode()
    return struct.pack('<I', len(data)) + data


def stalled_subscriber(master_uri: str) -> socket.socket:
    """A TCPROS connection to atlas_sim's /atlas/joint_states that will never be read."""
    master = xmlrpc.client.ServerProxy(master_uri)
    code, message, node_uri = master.lookupNode(STALLED, '/atlas_sim')
    assert code == 1, message
    code, message, protocol = xmlrpc.client.ServerProxy(node_uri).requestTopic(
        STALLED, '/atlas/joint_states', [['TCPROS']])
    assert code == 1, message
    _, host, port = protocol
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)  # fills at once
    sock.connect((host, port))
    header = b''.join(_field(text) for text in (
        f'callerid={STALLED}', 'topic=/atlas/joint_states', f'md5sum={JOINT_STATE_MD5}',
        'type=sensor_msgs/JointState', 'tcp_nodelay=1'))
    sock.sendall(struct.pack('<I', len(header)) + header)
    (length,) = struct.unpack('<I', sock.recv(4, socket.MSG_WAITALL))
    reply = sock.recv(length, socket.MSG_WAITALL)
    assert b'error=' not in reply, reply
    return sock  # and from here on, nothing is read


def test_a_stalled_subscriber_is_dropped_and_costs_nobody_a_message(
        atlas_launch: TestLaunch) -> None:
    atlas_launch.wait_ready()
    atlas_launch.wait_sim_s(1.0)
    pid = atlas_launch.pid_of('atlas_sim_node.py')
    before_kib = rss_kib(pid)
    sim0_s, wall0_s = atlas_launch.sim_time_s(), time.monotonic()
    sock = stalled_subscriber(atlas_launch.uri)
    try:
        atlas_launch.wait(lambda: DROPPED in atlas_launch.output(), DROP_TIMEOUT_S,
                          f'{STALLED} was not dropped')
        sim1_s, wall1_s = atlas_launch.sim_time_s(), time.monotonic()
        after_kib = rss_kib(pid)
        atlas_launch.wait_sim_s(2.0)  # the simulation goes on without it
    finally:
        sock.close()
    atlas_launch.interrupt()
    dropped = [line for line in atlas_launch.output().splitlines() if STALLED in line]
    assert len(dropped) == 1 and DROPPED in dropped[0], dropped
    assert before_kib is not None and after_kib is not None
    assert after_kib - before_kib < MEMORY_SLACK_KIB, (before_kib, after_kib)
    states = read_bag(atlas_launch.bag()).joint_states
    assert states is not None and missing_steps(states) == 0, 'the recorder lost no step'
    assert states.t_s[-1] > sim1_s
    rtf = (sim1_s - sim0_s) / (wall1_s - wall0_s)
    print(f'figures: stalled subscriber dropped after {wall1_s - wall0_s:.1f} s wall '
          f'({sim1_s - sim0_s:.1f} s sim: real-time factor {rtf:.2f} over the stall); '
          f'simulator RSS {before_kib} -> {after_kib} KiB; recorder: '
          f'{len(states.t_s)} joint states, none missing')
