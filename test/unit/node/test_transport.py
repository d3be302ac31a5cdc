"""transport.py: writing pre-serialized bytes to rospy's connections, counting subscribers."""

from __future__ import annotations

import socket
import threading
import time

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
    transport.ConnectionWriter().write(pub, b'data')
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
    transport.ConnectionWriter().write(pub, b'data')
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
    transport.ConnectionWriter().write(pub, b'data')  # no TypeError
    assert later.socket.sent == []


def test_a_type_error_of_an_open_publisher_is_not_hidden(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(transport.rospy, 'logdebug', lambda _msg: None)
    pub = FakePublisher([FakeConnection('/recorder', BrokenPipeError(32, 'Broken pipe'))])
    pub.remove_connection = lambda _connection: len(None)
    with pytest.raises(TypeError):
        transport.ConnectionWriter().write(pub, b'data')


def test_clock_goes_out_after_the_messages_stamped_with_it(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Seen in CI: the node stopped between /clock's send and the joint states', and the
    bag held a time no joint state was stamped with. The latest /clock is now sent last."""
    sent: list[tuple[str, bytes]] = []

    class Writer(transport.ConnectionWriter):
        def write(self, pub, data):
            sent.append((pub, bytes(data)))

    batch = transport.WireBatch(Writer())
    for step in (b'1', b'2'):
        batch.replace('clock', b'clock ' + step)
        batch.add('joint_states', b'state ' + step)
        batch.add('imu', b'imu ' + step)
    batch.flush()
    assert sent == [('joint_states', b'state 1state 2'), ('imu', b'imu 1imu 2'),
                    ('clock', b'clock 2')]
    batch.flush()
    assert len(sent) == 3, 'a flush sent twice'



def test_a_watcher_sees_what_each_flush_sent_after_it_was_written() -> None:
    events: list[tuple[str, str, bytes]] = []

    class Writer(transport.ConnectionWriter):
        def write(self, pub, data):
            events.append(('write', pub, bytes(data)))

    batch = transport.WireBatch(Writer())
    batch.watch('clock', lambda data: events.append(('seen', 'clock', bytes(data))))
    batch.replace('clock', b'clock 1')
    batch.add('imu', b'imu 1')
    batch.flush()
    batch.flush()  # nothing queued: nothing written, nothing seen
    assert events == [('write', 'imu', b'imu 1'), ('write', 'clock', b'clock 1'),
                      ('seen', 'clock', b'clock 1')]


# -- TCP subscribers that read slowly, or stop reading --------------------------------
class Clock:
    def __init__(self) -> None:
        self.now_s = 100.0

    def __call__(self) -> float:
        return self.now_s


class TcpSocket:
    """A non-blocking TCP socket whose kernel buffer holds `space` bytes; the subscriber
    reads `reads_per_slice` bytes each time the writer waits (a slice of fake time)."""

    def __init__(self, space: int, reads_per_slice: int) -> None:
        self.space = space
        self.free = space
        self.reads_per_slice = reads_per_slice
        self.timeout: float | None = None
        self.in_buffer = bytearray()
        self.received = bytearray()
        self.send_calls = 0

    def gettimeout(self):
        return self.timeout

    def setblocking(self, flag):
        self.timeout = None if flag else 0.0

    def send(self, data):
        assert self.timeout == 0.0, 'a TCP socket written while blocking'
        self.send_calls += 1
        taken = min(len(data), self.free)
        if taken == 0:
            raise BlockingIOError(11, 'Resource temporarily unavailable')
        self.in_buffer += bytes(data[:taken])
        self.free -= taken
        return taken

    def read_some(self) -> None:
        chunk = self.in_buffer[:self.reads_per_slice]
        del self.in_buffer[:len(chunk)]
        self.received += chunk
        self.free += len(chunk)

    def sendall(self, data):
        raise AssertionError('TCP sockets are written with send(), not sendall()')


class TcpConnection(FakeConnection):
    transport_type = 'TCPROS'

    def __init__(self, name: str, space: int = 1 << 20, reads_per_slice: int = 0) -> None:
        super().__init__(name)
        self.socket = TcpSocket(space, reads_per_slice)

    def close(self):
        self.closed = True
        self.done = True


class UdpConnection(FakeConnection):
    transport_type = 'UDPROS'


class Waits:
    """The writer's wait for a socket: a slice of fake time, during which subscribers read."""

    def __init__(self, clock: Clock) -> None:
        self.clock = clock
        self.slices = 0
        self.timeouts_s: list[float] = []
        self.during: list = []

    def __call__(self, sock: TcpSocket, timeout_s: float) -> bool:
        self.timeouts_s.append(timeout_s)
        self.slices += 1
        actions, self.during = self.during, []  # once (the hook waits too)
        for action in actions:
            action()
        self.clock.now_s += min(timeout_s, transport.STALL_PROBE_S)
        before = sock.free
        sock.read_some()
        return sock.free > before or sock.free > 0


def writer_and_waits(monkeypatch: pytest.MonkeyPatch) -> tuple:
    warnings: list[str] = []
    monkeypatch.setattr(transport.rospy, 'logwarn', warnings.append)
    clock = Clock()
    waits = Waits(clock)
    return transport.ConnectionWriter(clock, waits), waits, clock, warnings


def test_a_stalled_reader_holds_the_loop_one_slice_then_is_dropped_after_the_timeout(
        monkeypatch: pytest.MonkeyPatch) -> None:
    writer, waits, clock, warnings = writer_and_waits(monkeypatch)
    stalled = TcpConnection('/stalled', space=100, reads_per_slice=0)
    other = TcpConnection('/recorder')
    pub = FakePublisher([stalled, other])
    step = b'x' * 60
    writer.write(pub, step)
    writer.write(pub, step)  # the buffer fills: one slice waited, the rest kept
    assert waits.timeouts_s == [transport.STALL_PROBE_S]
    assert len(writer.backlogs[stalled].data) == 20
    steps = 2
    while clock.now_s - 100.0 < transport.SEND_TIMEOUT_S - 0.01:
        writer.write(pub, step)  # not waited for any more: the loop goes on at full speed
        steps += 1
        clock.now_s += 0.001
    assert waits.slices == 1
    assert stalled in pub.connections and warnings == []
    assert len(writer.backlogs[stalled].data) == steps * 60 - 100
    clock.now_s += 0.01
    writer.write(pub, step)
    steps += 1
    assert pub.connections == [other] and stalled.closed
    assert warnings == ['/clock: dropping subscriber /stalled: timed out: nothing taken for 2 s']
    assert writer.backlogs == {}, 'the stalled backlog is freed'
    assert other.socket.in_buffer == step * steps, 'the other subscriber lost nothing'


def test_a_backlog_past_its_bound_drops_the_subscriber_at_once(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(transport, 'MAX_BACKLOG_BYTES', 1000)
    writer, waits, clock, warnings = writer_and_waits(monkeypatch)
    stalled = TcpConnection('/stalled', space=100)
    pub = FakePublisher([stalled])
    for _ in range(11):
        writer.write(pub, b'y' * 100)
    assert stalled in pub.connections and len(writer.backlogs[stalled].data) == 1000
    writer.write(pub, b'y')
    assert pub.connections == [] and writer.backlogs == {}
    assert warnings == ['/clock: dropping subscriber /stalled: more than 1000 bytes not taken']
    assert waits.timeouts_s == [transport.STALL_PROBE_S], 'one slice waited in all'


def test_a_slow_reader_gets_back_pressure_and_loses_nothing_in_order(
        monkeypatch: pytest.MonkeyPatch) -> None:
    writer, waits, clock, warnings = writer_and_waits(monkeypatch)
    slow = TcpConnection('/recorder', space=50, reads_per_slice=7)
    pub = FakePublisher([slow])
    sent = b''.join(bytes([65 + i % 26]) * 40 for i in range(30))
    for i in range(30):
        writer.write(pub, sent[i * 40:(i + 1) * 40])
        assert writer.backlogs == {}, 'a reader that keeps taking bytes is waited for'
    while slow.socket.in_buffer:
        slow.socket.read_some()
    assert bytes(slow.socket.received) == sent
    assert warnings == [] and slow in pub.connections


def test_a_stalled_reader_that_reads_again_gets_its_backlog_first(
        monkeypatch: pytest.MonkeyPatch) -> None:
    writer, waits, clock, warnings = writer_and_waits(monkeypatch)
    conn = TcpConnection('/recorder', space=30, reads_per_slice=0)
    pub = FakePublisher([conn])
    sent = b''.join(bytes([97 + i]) * 20 for i in range(10))
    for i in range(5):
        writer.write(pub, sent[i * 20:(i + 1) * 20])
    assert len(writer.backlogs[conn].data) == 70
    conn.socket.reads_per_slice = 9
    conn.socket.read_some()  # it reads again (a disk that was slow for a moment)
    for i in range(5, 10):
        writer.write(pub, sent[i * 20:(i + 1) * 20])
    assert writer.backlogs == {}, 'back to normal'
    while conn.socket.in_buffer:
        conn.socket.read_some()
    assert bytes(conn.socket.received) == sent
    assert warnings == []


def test_nothing_backlogged_costs_one_send_per_connection(
        monkeypatch: pytest.MonkeyPatch) -> None:
    writer, waits, clock, warnings = writer_and_waits(monkeypatch)
    connections = [TcpConnection('/a'), TcpConnection('/b')]
    pub = FakePublisher(connections)
    for _ in range(3):
        writer.write(pub, b'step')
    assert [c.socket.send_calls for c in connections] == [3, 3]
    assert waits.slices == 0 and clock.now_s == 100.0


def test_udp_connections_keep_their_sendall(monkeypatch: pytest.MonkeyPatch) -> None:
    writer, waits, clock, warnings = writer_and_waits(monkeypatch)
    udp = UdpConnection('/cpp_tutorial')
    udp.socket.gettimeout = lambda: None
    udp.socket.settimeout = lambda t: setattr(udp.socket, 'timeout', t)
    pub = FakePublisher([udp])
    writer.write(pub, b'two messages')
    assert udp.socket.sent == [b'two messages'] and udp.socket.timeout == transport.SEND_TIMEOUT_S
    assert writer.backlogs == {}


def test_the_shutdown_hook_sends_what_a_live_subscriber_has_not_taken(
        monkeypatch: pytest.MonkeyPatch) -> None:
    writer, waits, clock, warnings = writer_and_waits(monkeypatch)
    conn = TcpConnection('/recorder', space=10, reads_per_slice=0)
    pub = FakePublisher([conn])
    writer.write(pub, b'0123456789abcdef')
    writer.write(pub, b'ghij')
    assert bytes(writer.backlogs[conn].data) == b'abcdefghij'
    conn.socket.reads_per_slice = 4  # the recorder reads again: the hook waits for it
    writer.drain()
    conn.socket.read_some()
    conn.socket.read_some()
    assert bytes(conn.socket.received) == b'0123456789abcdefghij'
    assert writer.backlogs == {}


def test_the_shutdown_hook_in_a_write_drains_only_while_it_waits(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """SIGINT runs rospy's hooks in the loop's thread, inside whatever it was doing."""
    writer, waits, clock, warnings = writer_and_waits(monkeypatch)
    conn = TcpConnection('/recorder', space=10, reads_per_slice=0)
    pub = FakePublisher([conn])
    writer.write(pub, b'0123456789')
    writer.write(pub, b'abcd')  # waits one slice: the hook runs there
    conn.socket.reads_per_slice = 4
    conn.socket.read_some()
    left_by_hook: list[dict] = []
    waits.during.append(lambda: (writer.drain(), left_by_hook.append(dict(writer.backlogs))))
    writer.write(pub, b'efgh')  # reads again: waited for, the hook drains from the wait
    assert left_by_hook == [{}], 'the hook itself drained (the writer noted as holder)'
    assert waits.during == [] and writer.backlogs == {}
    while conn.socket.in_buffer:
        conn.socket.read_some()
    assert bytes(conn.socket.received) == b'0123456789abcdefgh', 'nothing twice, in order'
    # Inside a write but not in its wait (a send in progress): the hook leaves it.
    blocked = TcpConnection('/slow', space=2)
    writer.write(FakePublisher([blocked]), b'xyzw')
    blocked.socket.reads_per_slice = 3  # it would take the rest now
    writer.lock.acquire()
    writer._holder = threading.get_ident()
    try:
        writer.drain()
    finally:
        writer._holder = None
        writer.lock.release()
    assert bytes(writer.backlogs[blocked].data) == b'zw'


class SocketPairConnection(FakeConnection):
    """A TCPROS connection over a real socket pair: `peer` is the subscriber's end."""

    transport_type = 'TCPROS'

    def __init__(self, name: str) -> None:
        super().__init__(name)
        self.socket, self.peer = socket.socketpair()
        for sock, option in ((self.socket, socket.SO_SNDBUF), (self.peer, socket.SO_RCVBUF)):
            sock.setsockopt(socket.SOL_SOCKET, option, 4096)

    def close(self):
        self.closed = self.done = True
        self.socket.close()


def test_real_sockets_a_stalled_reader_is_left_then_drained_in_order(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """The same with the kernel's buffers and poll(): a write to a reader that takes
    nothing returns (after one slice) with the rest kept; the hook sends it all once the
    reader reads again."""
    monkeypatch.setattr(transport.rospy, 'logwarn', lambda msg: pytest.fail(msg))
    writer = transport.ConnectionWriter()
    conn = SocketPairConnection('/recorder')
    pub = FakePublisher([conn])
    sent = bytes(range(256)) * 4096  # 1 MiB: far more than both buffers
    writer.write(pub, sent[:1 << 19])
    writer.write(pub, sent[1 << 19:])
    assert conn.socket.gettimeout() == 0.0
    assert len(writer.backlogs[conn].data) > 1 << 19, 'kept, not waited for'
    received = bytearray()

    def read() -> None:
        while len(received) < len(sent):
            received.extend(conn.peer.recv(1 << 16))

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    writer.drain(timeout_s=60.0)  # a guard only
    reader.join(60.0)
    assert writer.backlogs == {} and bytes(received) == sent
    conn.close()
    conn.peer.close()


class _SlowTransport:
    """A connection rospy's writer thread relays to, 20 ms a message."""

    def __init__(self) -> None:
        self.done = False
        self.written: list[bytes] = []

    def set_cleanup_callback(self, _callback: object) -> None:
        pass

    def write_data(self, data: bytes) -> bool:
        time.sleep(0.02)
        if data:  # the flush's barriers are empty
            self.written.append(data)
        return True


def test_flush_queued_returns_once_rospy_s_writer_has_written_everything() -> None:
    """The node's last sim_config and log line before a divergence shutdown: published into
    rospy's queued connection, written by its thread; the flush waits for them."""
    from types import SimpleNamespace

    from rospy.topics import QueuedConnection

    slow = _SlowTransport()
    queued = QueuedConnection(slow, 100)
    try:
        for k in range(3):
            queued.write_data(b'config %d' % k)
        transport.flush_queued(SimpleNamespace(impl=SimpleNamespace(connections=[queued])))
        assert slow.written == [b'config 0', b'config 1', b'config 2']
    finally:
        slow.done = True
        with queued._lock:
            queued._cond_data_available.notify()
        queued._thread.join(timeout=5.0)
