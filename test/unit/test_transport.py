"""transport.py: writing pre-serialized bytes to rospy's connections, counting subscribers."""

from __future__ import annotations

import pytest

from tutorial_atlas_control.node import transport


class FakeSocket:
    def __init__(self, error: Exception | None = None) -> None:
        self.error = error
        self.sent = []

    def gettimeout(self):
        return transport.SEND_TIMEOUT_S

    def sendall(self, data):
        if self.error is not None:
            raise self.error
        self.sent.append(data)


class FakeConnection:
    def __init__(self, name: str, error: Exception | None = None) -> None:
        self.endpoint_id = name
        self.socket = FakeSocket(error)
        self.done = False
        self.closed = False

    def close(self):
        self.closed = True


class FakePublisher:
    resolved_name = '/clock'

    def __init__(self, connections: list[FakeConnection]) -> None:
        self.impl = self
        self.connections = list(connections)
        self.closed = False

    def remove_connection(self, connection):
        self.connections.remove(connection)


def test_a_subscriber_connected_twice_counts_once():
    """rospy may hold two connections from one node for a moment (seen: a flood started
    with only the simulator connected, and the recorder missed 114 of its commands)."""
    pub = FakePublisher([FakeConnection('/atlas_sim'), FakeConnection('/atlas_sim')])
    assert transport.subscriber_names(pub) == {'/atlas_sim'}
    pub.connections.append(FakeConnection('/recorder'))
    assert transport.subscriber_names(pub) == {'/atlas_sim', '/recorder'}


def test_a_subscriber_that_left_is_dropped_quietly_a_stalled_one_with_a_warning(monkeypatch):
    warnings = []
    monkeypatch.setattr(transport.rospy, 'logwarn', warnings.append)
    monkeypatch.setattr(transport.rospy, 'logdebug', lambda _msg: None)
    healthy = FakeConnection('/probe')
    left = FakeConnection('/traj_yaml', BrokenPipeError(32, 'Broken pipe'))
    stalled = FakeConnection('/slow', TimeoutError('timed out'))
    pub = FakePublisher([healthy, left, stalled])
    transport.write_to_connections(pub, b'data')
    assert healthy.socket.sent == [b'data']
    assert pub.connections == [healthy]
    assert left.closed and stalled.closed
    assert len(warnings) == 1 and '/slow' in warnings[0], warnings


class ClosingSocket(FakeSocket):
    """A socket whose publisher rospy shuts down (another thread) while it is written."""

    def __init__(self, pub: FakePublisher) -> None:
        super().__init__()
        self.pub = pub

    def sendall(self, data: bytes) -> None:
        # rospy's _PublisherImpl.close(): closed, connections closed and forgotten, and
        # remove_connection() fails from then on (its listener list is gone).
        self.pub.closed = True
        self.pub.connections.clear()
        self.pub.remove_connection = None
        raise OSError(9, 'Bad file descriptor')


def test_a_publisher_shut_down_during_a_send_is_left_quietly(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """rosnode kill or Ctrl-C shuts rospy down while the loop flushes: no traceback."""
    warnings = []
    monkeypatch.setattr(transport.rospy, 'logwarn', warnings.append)
    closing = FakeConnection('/atlas_sim')
    later = FakeConnection('/recorder')
    pub = FakePublisher([closing, later])
    closing.socket = ClosingSocket(pub)
    transport.write_to_connections(pub, b'data')
    assert later.socket.sent == []
    assert warnings == []


class ClosedDuringRemoval(FakePublisher):
    """rospy closes the publisher between the send's failure and its removal (seen with a
    second atlas.launch on the same master: TypeError in rospy's remove_connection)."""

    def remove_connection(self, connection):
        self.closed = True
        self.connections.clear()
        listeners = None
        for _listener in listeners:  # rospy's _PublisherImpl.remove_connection, after close()
            pass


def test_a_publisher_closed_while_a_connection_is_removed_is_left_quietly(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(transport.rospy, 'logdebug', lambda _msg: None)
    left = FakeConnection('/recorder', BrokenPipeError(32, 'Broken pipe'))
    later = FakeConnection('/probe')
    pub = ClosedDuringRemoval([left, later])
    transport.write_to_connections(pub, b'data')  # no TypeError
    assert later.socket.sent == []


def test_a_type_error_of_an_open_publisher_is_not_hidden(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(transport.rospy, 'logdebug', lambda _msg: None)
    pub = FakePublisher([FakeConnection('/recorder', BrokenPipeError(32, 'Broken pipe'))])
    pub.remove_connection = lambda _connection: len(None)
    with pytest.raises(TypeError):
        transport.write_to_connections(pub, b'data')


def test_clock_goes_out_after_the_messages_stamped_with_it(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Seen in CI: the node stopped between /clock's send and the joint states', and the
    bag held a time no joint state was stamped with. The latest /clock is now sent last."""
    sent: list[tuple[str, bytes]] = []
    monkeypatch.setattr(transport, 'write_to_connections',
                        lambda pub, data: sent.append((pub, bytes(data))))
    batch = transport.WireBatch()
    for step in (b'1', b'2'):
        batch.replace('clock', b'clock ' + step)
        batch.add('joint_states', b'state ' + step)
        batch.add('imu', b'imu ' + step)
    batch.flush()
    assert sent == [('joint_states', b'state 1state 2'), ('imu', b'imu 1imu 2'),
                    ('clock', b'clock 2')]
    batch.flush()
    assert len(sent) == 3, 'a flush sent twice'
