"""Sending pre-serialized messages (msgs/wire.py) straight to rospy's TCPROS connections.

rospy's Publisher.publish() serializes with genpy and hands the bytes to a writer thread
per subscriber; the simulator's loop instead collects each step's bytes per publisher in a
WireBatch and writes each publisher's batch to its connections with one sendall on
flush() (TCPROS is a byte stream: messages back to back are valid). The publishers are
created with queue_size=None, so the sends are synchronous: a slow subscriber slows the
loop rather than losing messages, until it is dropped (SEND_TIMEOUT_S).
"""

from __future__ import annotations

import rospy
from rospy.impl.tcpros_base import TransportTerminated

__all__ = ['SEND_TIMEOUT_S', 'WireBatch', 'subscriber_names', 'write_to_connections']

#: A subscriber that accepts nothing for this long (s) is dropped rather than left to stall
#: the simulation: sends are synchronous so that slow subscribers lose nothing.
SEND_TIMEOUT_S = 2.0


def write_to_connections(pub: rospy.Publisher, data: bytes | bytearray) -> None:
    """Send already-serialized TCPROS bytes to every subscriber of `pub`.

    The socket is written directly (rospy's write_data mis-handles a send timeout); a
    subscriber that is gone, or accepts nothing for SEND_TIMEOUT_S, is dropped. Once rospy
    has shut the publisher down (node shutdown, from another thread), nothing is sent.
    """
    impl = pub.impl
    for connection in list(impl.connections):
        sock = getattr(connection, 'socket', None)
        try:
            if sock is None or connection.done:
                raise TransportTerminated('connection closed')
            if sock.gettimeout() is None:
                sock.settimeout(SEND_TIMEOUT_S)
            sock.sendall(data)
        except (TransportTerminated, OSError) as err:  # socket.timeout is an OSError
            if impl.closed:  # rospy closed every connection and cannot remove one any more
                return
            if isinstance(err, (BrokenPipeError, ConnectionResetError, ConnectionRefusedError)):
                # The subscriber exited (traj_yaml.py at its end): routine, as in rospy.
                # Refused: a UDPROS subscriber's port is closed (node/udpros.py).
                rospy.logdebug(f'{pub.resolved_name}: subscriber {connection.endpoint_id} left')
            elif not isinstance(err, TransportTerminated):
                rospy.logwarn(f'{pub.resolved_name}: dropping subscriber '
                              f'{connection.endpoint_id}: {err}')
            try:
                impl.remove_connection(connection)
            except (TypeError, AttributeError):
                # rospy closed the publisher after the check above (another thread: a
                # shutdown, such as a second atlas_sim registering): its listener list is
                # gone, and with it every connection. Nothing left to send to.
                if impl.closed:
                    return
                raise
            connection.close()


def subscriber_names(pub: rospy.Publisher) -> set[str]:
    """The nodes connected to `pub` now.

    Count these, not get_num_connections(): when a subscriber connects twice at once
    (rospy does, on two quick publisher updates), the publisher holds both connections for a
    moment before dropping one, so a node counts twice and "the simulator and the recorder
    are connected" can be true with only the simulator.
    """
    return {connection.endpoint_id for connection in list(pub.impl.connections)}


class WireBatch:
    """Per-publisher byte batches, written on flush() with one sendall per connection.

    Replaced outlets (/clock: only its latest value goes out) are written after the
    batches, so a subscriber never gets a time before the messages stamped with it, even
    when the node stops in the middle of a flush.
    """

    def __init__(self) -> None:
        self.pending: dict[rospy.Publisher, bytearray] = {}
        self.latest: dict[rospy.Publisher, bytearray] = {}

    @staticmethod
    def wanted(pub: rospy.Publisher) -> bool:
        """Anyone subscribed? (rospy skips serializing otherwise; so do we)."""
        return bool(pub.impl.connections)

    def add(self, pub: rospy.Publisher, data: bytes | bytearray) -> None:
        """Append a copy of `data` (TCPROS-framed messages) to `pub`'s batch."""
        batch = self.pending.get(pub)
        if batch is None:
            self.pending[pub] = bytearray(data)
        else:
            batch += data

    def replace(self, pub: rospy.Publisher, data: bytes | bytearray) -> None:
        """Queue `data` instead of anything still queued for `pub` (e.g. /clock), to be
        sent after every batch."""
        self.latest[pub] = bytearray(data)

    def flush(self) -> None:
        pending, self.pending = self.pending, {}
        latest, self.latest = self.latest, {}
        for batches in (pending, latest):
            for pub, data in batches.items():
                write_to_connections(pub, data)
