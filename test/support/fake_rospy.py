"""A SimNode without a ROS graph: rospy's publishers, subscribers, services and parameters
faked, each publisher's one subscriber a socket to /dev/null or to a draining process.

What is left is the node's own per-step work (commands, law, mj_step, serializing,
batching and the writes), for the benchmark (bench/node_loop.py, which times it) and for
tests of the node's shell (test/unit/node/test_sim_node.py).
"""

from __future__ import annotations

import contextlib
import os
import socket
import subprocess
import sys
from collections.abc import Collection, Iterator, Mapping
from pathlib import Path
from types import SimpleNamespace
from typing import Any
from unittest import mock

from tutorial_atlas_control import topics
from tutorial_atlas_control.sim.simulator import AtlasSimulator
from tutorial_atlas_control.stepping.loop import LoopSettings

__all__ = ['LAUNCH_RATES_HZ', 'UNHEARD_TOPICS', 'FakePublisher', 'Sinks', 'fake_ros_node']

#: atlas.launch's rates (Hz of sim time), without /tf.
LAUNCH_RATES_HZ = {'joint_states': 1000.0, 'odom': 100.0, 'imu': 1000.0, 'contact': 1000.0}
#: The topics no fake subscriber listens to: as in a live launch, where the recorder
#: subscribes to what it records and DRCSim's 1 kHz duplicates are not recorded.
UNHEARD_TOPICS = frozenset(topic.name for topic in topics.INTERFACE
                           if topic.delivery.loop and topic.on_demand and not topic.recorded)
#: What the fake sockets report as their send timeout (s): set, so transport.py leaves it.
SOCKET_TIMEOUT_S = 2.0


class NullSocket:
    """A subscriber's socket that takes every byte with one write(2) to /dev/null."""

    def __init__(self) -> None:
        self.fd = os.open(os.devnull, os.O_WRONLY)

    def gettimeout(self) -> float:
        return SOCKET_TIMEOUT_S

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


class Sinks:
    """Where the fake publishers' bytes go: /dev/null, or (tcp) one loopback TCP connection
    per publisher to a draining subprocess, as to a recorder: then each write costs what it
    costs the node, the send and the receiver's wake-up."""

    def __init__(self, tcp: bool) -> None:
        self.sockets: list[Any] = []
        self.process: subprocess.Popen[str] | None = None
        if tcp:
            self.process = subprocess.Popen([sys.executable, '-c', _DRAIN],
                                            stdout=subprocess.PIPE, text=True)
            self.port = int(self.process.stdout.readline())

    def new(self) -> Any:
        """A socket-like object for one more subscriber connection."""
        if self.process is None:
            sock: Any = NullSocket()
        else:
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


class FakePublisher:
    """rospy.Publisher as transport.py sees it: one subscriber connection (none for
    UNHEARD_TOPICS, or `heard` False). `published` keeps what went through publish() (the
    latched /atlas/sim_config)."""

    resolved_name = 'fake'
    #: (ROS type, latched) as rospy.Publisher was given them.
    advertised: tuple[str, bool] = ('', False)

    def __init__(self, sinks: Sinks, topic: str = '', heard: bool | None = None) -> None:
        self.topic = topic
        if heard is None:
            heard = topic not in UNHEARD_TOPICS
        connections = ([SimpleNamespace(socket=sinks.new(), done=False, endpoint_id='fake')]
                       if heard else [])
        self.impl = SimpleNamespace(connections=connections)
        self.published: list[object] = []

    def publish(self, msg: object) -> None:
        self.published.append(msg)


@contextlib.contextmanager
def fake_ros_node(sim: AtlasSimulator, steps: int, tcp: bool = False,
                  rates_hz: Mapping[str, float] = LAUNCH_RATES_HZ,
                  params: Mapping[str, object] | None = None,
                  score_dir: Path | None = None,
                  heard: Collection[str] | None = None) -> Iterator[Any]:
    """A real SimNode (real_time_factor 0) around `sim`, on fake rospy (with `score_dir`,
    scoring the VRC course into it).

    Each publisher has one subscriber (see Sinks), but those of UNHEARD_TOPICS, or, given
    `heard`, each publisher of a topic in `heard` and no other; rospy.is_shutdown() ends
    spin() after `steps` steps. The node's `fake_publishers` maps each topic to its
    FakePublisher.
    """
    from tutorial_atlas_control.node import sim_node

    sinks = Sinks(tcp)
    calls = {'left': steps}
    publishers: dict[str, FakePublisher] = {}
    known = dict(params or {})

    def is_shutdown() -> bool:
        calls['left'] -= 1
        return calls['left'] < 0

    def publisher(topic: str, msg_class: type, *_args: object, **kwargs: object) -> FakePublisher:
        publishers[topic] = FakePublisher(sinks, topic,
                                          None if heard is None else topic in heard)
        publishers[topic].advertised = (msg_class._type, bool(kwargs.get('latch', False)))
        return publishers[topic]

    try:
        with mock.patch.multiple(sim_node.rospy, Publisher=publisher,
                                 Subscriber=mock.DEFAULT, Service=mock.DEFAULT,
                                 get_param=lambda name, default=None: known.get(name, default),
                                 has_param=lambda name: name in known, is_shutdown=is_shutdown,
                                 signal_shutdown=mock.DEFAULT, loginfo=mock.DEFAULT,
                                 logwarn=mock.DEFAULT, logwarn_throttle=mock.DEFAULT,
                                 logwarn_throttle_identical=mock.DEFAULT,
                                 logerr=mock.DEFAULT, logerr_throttle=mock.DEFAULT,
                                 logfatal=mock.DEFAULT), \
                mock.patch.object(sim_node, 'serve_udpros'):  # no rospy node to register with
            node = sim_node.SimNode(sim, LoopSettings(dict(rates_hz), score_dir=score_dir),
                                    gui=False)
            node.fake_publishers = publishers
            yield node
    finally:
        sinks.close()
