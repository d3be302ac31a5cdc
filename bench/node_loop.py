"""The node's per-step work without a ROS graph: bare mj_step, law + mj_step, and SimNode.spin.

On a shared 2-core machine a node-level figure moves with everyone else's load; these
loops run in one process, so an A/B of two variants (compiled vs numpy law, one node
loop vs another) compares like with like. `python3 bench/node_loop.py` prints µs per
step of each (interleaved rounds, best of them).
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
from pathlib import Path
from types import SimpleNamespace
from unittest import mock

sys.path.insert(0, str(Path(__file__).resolve().parent))

import offline  # noqa: E402
from offline import make_simulator  # noqa: E402

#: The node's law runs this long (s of sim time) before the bare physics is timed: past
#: the 1 s torso pin, feet in contact, the robot standing.
STANDING_AFTER_S = 1.5
#: The bare loop restores the standing snapshot this often, so the held torques never let
#: the robot drift far from standing (a falling robot has other contacts, another cost):
#: with the torques held, the pelvis sinks 2 mm in 200 steps, 14 mm in 500 (by then on one
#: contact instead of 8) and 20 cm in 1000.
RESTORE_EVERY_STEPS = 200


def bare_physics_run(steps: int = 5000) -> float:
    """Steps per wall second of mujoco.mj_step alone, from the standing state.

    The node's law runs until STANDING_AFTER_S; the state is snapshot (mj_getState,
    mjSTATE_INTEGRATION) and mj_step timed with the last torques held in ctrl, the
    snapshot restored every RESTORE_EVERY_STEPS steps (outside the timed blocks).
    """
    import mujoco
    import numpy as np

    sim = make_simulator()
    while sim.sim_time_ns < STANDING_AFTER_S * 1e9:
        sim.step()
    model, data = sim.model, sim.data
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    snapshot = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, snapshot, spec)
    step = mujoco.mj_step
    elapsed_s = 0.0
    done = 0
    while done < steps:
        mujoco.mj_setState(model, data, snapshot, spec)
        block = min(RESTORE_EVERY_STEPS, steps - done)
        start = time.perf_counter()
        for _ in range(block):
            step(model, data)
        elapsed_s += time.perf_counter() - start
        done += block
    return steps / elapsed_s


class _NullSocket:
    """A subscriber's socket that takes every byte with one write(2) to /dev/null."""

    def __init__(self) -> None:
        self.fd = os.open(os.devnull, os.O_WRONLY)

    def gettimeout(self) -> float:
        return 2.0

    def sendall(self, data: bytes) -> None:
        os.write(self.fd, data)

    def close(self) -> None:
        os.close(self.fd)


#: The subscriber process of the TCP sinks: accepts connections, reads and discards.
_DRAIN = """
import selectors, socket
server = socket.create_server(('127.0.0.1', 0))
print(server.getsockname()[1], flush=True)
selector = selectors.DefaultSelector()
selector.register(server, selectors.EVENT_READ)
while True:
    for key, _ in selector.select():
        if key.fileobj is server:
            selector.register(server.accept()[0], selectors.EVENT_READ)
        elif not key.fileobj.recv(1 << 20):
            selector.unregister(key.fileobj)
"""


class _Sinks:
    """Where the fake publishers' bytes go: /dev/null, or (tcp) one loopback TCP connection
    per publisher to a draining subprocess, as to a recorder: then each write costs what it
    costs the node, the send and the receiver's wake-up."""

    def __init__(self, tcp: bool) -> None:
        self.sockets: list = []
        self.process = None
        if tcp:
            import subprocess

            self.process = subprocess.Popen([sys.executable, '-c', _DRAIN],
                                            stdout=subprocess.PIPE, text=True)
            self.port = int(self.process.stdout.readline())

    def new(self):  # noqa: ANN201 - a socket-like object
        if self.process is None:
            sock = _NullSocket()
        else:
            import socket

            sock = socket.create_connection(('127.0.0.1', self.port))
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.sockets.append(sock)
        return sock

    def close(self) -> None:
        for sock in self.sockets:
            sock.close()
        if self.process is not None:
            self.process.kill()
            self.process.wait()


class _FakePublisher:
    """rospy.Publisher as wire.py sees it: one subscriber connection."""

    resolved_name = 'bench'

    def __init__(self, sinks: _Sinks) -> None:
        connection = SimpleNamespace(socket=sinks.new(), done=False, endpoint_id='bench')
        self.impl = SimpleNamespace(connections=[connection])

    def publish(self, *_args: object) -> None:
        pass


@contextlib.contextmanager
def fake_ros_node(steps: int, warmup_steps: int = 1500, compiled_law: bool = True,
                  tcp: bool = False):  # noqa: ANN201
    """A real SimNode (real_time_factor 0, the launch's rates) on fake rospy, standing.

    Each publisher has one subscriber (see _Sinks); rospy.is_shutdown() ends spin() after
    `steps` steps.
    """
    from tutorial_atlas_control.node import sim_node

    sinks = _Sinks(tcp)
    sim = make_simulator()
    if not compiled_law:
        sim._compiled_law = None
    for _ in range(warmup_steps):
        sim.step()
    calls = {'left': steps}

    def is_shutdown() -> bool:
        calls['left'] -= 1
        return calls['left'] < 0

    params: dict[str, object] = {}
    try:
        with mock.patch.multiple(sim_node.rospy, Publisher=lambda *a, **k: _FakePublisher(sinks),
                                 Subscriber=mock.DEFAULT, Service=mock.DEFAULT,
                                 get_param=lambda name, default=None: params.get(name, default),
                                 has_param=lambda name: name in params, is_shutdown=is_shutdown,
                                 loginfo=mock.DEFAULT, logwarn=mock.DEFAULT):
            yield sim_node.SimNode(sim, real_time_factor=0.0, paused=False,
                                   rates_hz={'joint_states': 1000.0, 'odom': 100.0,
                                             'imu': 1000.0, 'contact': 1000.0}, gui=False)
    finally:
        sinks.close()


def node_spin_run(steps: int = 5000, warmup_steps: int = 1500, compiled_law: bool = True,
                  tcp: bool = False) -> float:
    """CPU µs (this process, user + system) per step of the real SimNode.spin at rtf 0.

    What is left without ROS is the node's own per-step work: commands, law, mj_step,
    serializing, batching and the writes.
    """
    with fake_ros_node(steps, warmup_steps, compiled_law, tcp) as node:
        start = time.process_time()
        node.spin()
        return (time.process_time() - start) / steps * 1e6


def main() -> int:
    rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 3
    best: dict[str, float] = {}
    for _ in range(rounds):
        figures = {
            'bare mj_step': 1e6 / bare_physics_run(),
            'law (C) + mj_step': 1e6 / offline.physics_run(compiled_law=True),
            'law (numpy) + mj_step': 1e6 / offline.physics_run(compiled_law=False),
            'node spin, C law': node_spin_run(),
            'node spin, numpy law': node_spin_run(compiled_law=False),
            'node spin, C law, TCP': node_spin_run(tcp=True),
        }
        for name, value in figures.items():
            best[name] = min(best.get(name, value), value)
        print('  '.join(f'{name}: {value:.1f}' for name, value in figures.items()), flush=True)
    print(f'best of {rounds} (µs per step, load {os.getloadavg()[0]:.1f}):')
    for name, value in best.items():
        print(f'  {name:<24} {value:8.1f}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
