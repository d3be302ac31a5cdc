"""Sending pre-serialized messages (msgs/wire.py) straight to rospy's TCPROS connections.

rospy's Publisher.publish() serializes with genpy and hands the bytes to a writer thread
per subscriber; the simulator's loop instead collects each step's bytes per publisher in a
WireBatch and writes each publisher's batch to its connections with one send on flush()
(TCPROS is a byte stream: messages back to back are valid). The publishers are created
with queue_size=None: no rospy queue, the loop writes the sockets itself (ConnectionWriter).

A TCP subscriber that reads slowly but keeps reading (the bag recorder at
real_time_factor:=0) gets back-pressure: the loop waits for it and it loses nothing. One
that stops reading is not waited for beyond STALL_PROBE_S: what it has not
taken is kept in a bounded backlog while the loop and the other subscribers go on, and it
is dropped once it has accepted nothing for SEND_TIMEOUT_S or its backlog passes
MAX_BACKLOG_BYTES.
"""

from __future__ import annotations

import select
import socket
import threading
import time
from collections.abc import Callable, Collection

import rospy
from rospy.impl import rosout, tcpros_base
from rospy.impl.tcpros_base import TransportTerminated

from tutorial_atlas_control.node.held_sends import HeldSends

__all__ = ['MAX_BACKLOG_BYTES', 'SEND_TIMEOUT_S', 'STALL_PROBE_S', 'ConnectionWriter',
           'WireBatch', 'flush_queued', 'flush_rosout', 'subscriber_names', 'widen_accept_queue']

#: A subscriber that accepts nothing for this long (s) is dropped: slow subscribers lose
#: nothing, stalled ones do not hold their bytes (and the node's memory) forever.
SEND_TIMEOUT_S = 2.0
#: How long (s) one flush waits for a TCP subscriber whose kernel buffer is full before it
#: keeps the rest in a backlog and goes on; as long as the subscriber takes bytes within
#: each such slice, the flush keeps waiting (back-pressure, nothing lost).
STALL_PROBE_S = 0.05
#: A backlog past this (bytes) drops its subscriber at once: the memory bound per connection.
MAX_BACKLOG_BYTES = 16 * 1024 * 1024


def widen_accept_queue() -> None:
    """Let the node's TCPROS server queue as many connections as the kernel allows.

    rospy listens with a backlog of 5. At startup the recorder, rosout and the tools connect
    to a dozen of the simulator's topics at once while its accept thread waits for the GIL:
    the kernel drops the connections past 5 and their subscribers retry a second or more
    later (TcpExtListenOverflows), missing what was published meanwhile (a forced-divergence
    run lost /atlas/sim_config from its bag). Call after init_node, before advertising.
    """
    tcpros_base.start_tcpros_server()  # what the first publisher does; idempotent
    server = tcpros_base._tcpros_server  # rospy offers no setter
    if server is not None and server.tcp_ros_server is not None:  # else rospy has logged why
        server.tcp_ros_server.server_sock.listen(socket.SOMAXCONN)  # Linux: updates the backlog


def flush_rosout(timeout_s: float = 2.0) -> None:
    """Return once rospy has written every /rosout message logged so far (or after
    `timeout_s`): its /rosout publisher hands each line to a writer thread per subscriber,
    and a shutdown right after a log call closed the connection before the simulator's last
    line (why it stopped) reached the recorder (a forced-divergence run beside a busy core)."""
    publisher = rosout._rosout_pub
    if publisher is not None:
        flush_queued(publisher, timeout_s)


def flush_queued(publisher: rospy.Publisher, timeout_s: float = 2.0) -> None:
    """Return once `publisher`'s writer threads have written every message published so far
    (or after `timeout_s`).

    Per connection, two empty barriers in turn: the writer takes its queue as one batch, so
    once the second barrier is taken the batch holding the first, and every message before
    it, has been written. rospy offers no flush; its QueuedConnection is used as it is.
    """
    deadline = time.monotonic() + timeout_s
    for connection in list(publisher.impl.connections):
        lock = getattr(connection, '_lock', None)
        queue = getattr(connection, '_queue', None)
        wake = getattr(connection, '_cond_data_available', None)
        if lock is None or queue is None or wake is None:  # a synchronous connection
            continue
        for _barrier in range(2):
            with lock:  # the writer swaps in a new list as it takes a batch: append to today's
                connection._queue.append(b'')
                wake.notify()
            while time.monotonic() < deadline and not connection.done:
                with lock:
                    if not connection._queue:
                        break
                time.sleep(0.001)


def wait_writable(sock: socket.socket, timeout_s: float) -> bool:
    """True once `sock` can take bytes, False after `timeout_s` (poll: no FD_SETSIZE limit)."""
    poller = select.poll()
    poller.register(sock, select.POLLOUT)
    return bool(poller.poll(max(0.0, timeout_s) * 1000.0))


class Backlog:
    """What one TCP connection has not taken yet, and when it last took something."""

    __slots__ = ('data', 'progress_s')

    def __init__(self, data: bytes | bytearray, progress_s: float) -> None:
        self.data = bytearray(data)
        self.progress_s = progress_s


class BacklogFull(OSError):
    """A backlog past MAX_BACKLOG_BYTES (dropped like a send timeout, with its reason)."""


class _Holding:
    """`with` it: a ConnectionWriter's lock taken by this thread, noted as its holder (what
    drain() reads when a SIGINT lands in the middle of a send)."""

    __slots__ = ('writer',)

    def __init__(self, writer: ConnectionWriter) -> None:
        self.writer = writer

    def __enter__(self) -> None:
        writer = self.writer
        writer.lock.acquire()
        writer._holder = threading.get_ident()

    def __exit__(self, *exc_info: object) -> None:
        writer = self.writer
        writer._holder = None
        writer.lock.release()


class ConnectionWriter:
    """Writes already-serialized TCPROS bytes to every subscriber of a publisher.

    The socket is written directly (rospy's write_data mis-handles a send timeout). TCP
    sockets are made non-blocking: with nothing backlogged, a flush costs one send() per
    connection. UDPROS connections (node/udpros.py's DatagramStream) keep their sendall,
    which cuts the batch into datagrams and never waits for the subscriber.
    """

    def __init__(self, clock: Callable[[], float] = time.monotonic,
                 wait: Callable[[socket.socket, float], bool] = wait_writable,
                 held: HeldSends | None = None) -> None:
        self.clock = clock
        self.wait = wait
        #: The bag recorder's bytes, sent every few ms rather than at each flush (held_sends.py).
        self.held = held if held is not None else HeldSends(())
        #: TCP connections with bytes not taken yet (only those: the hot path is a miss).
        self.backlogs: dict[object, Backlog] = {}
        #: Held by write() and drain(): drain() runs in rospy's SIGINT handler, which runs
        #: in the loop's thread, possibly in the middle of a write (see drain()).
        self.lock = threading.Lock()
        self._holder: int | None = None
        self._holding = _Holding(self)
        #: True only while write() waits for a socket with every backlog committed.
        self._waiting = False

    def write(self, pub: rospy.Publisher, data: bytes | bytearray) -> None:
        """Send `data` to every subscriber of `pub`; drop those that left or stalled. Once
        rospy has shut the publisher down (node shutdown, from another thread), nothing
        is sent."""
        with self._holding:
            self._write(pub, data)

    def begin_flush(self) -> None:
        """A flush starts (WireBatch.flush): it may release what is held."""
        self.held.begin_flush()

    def release_held(self, written_next: Collection[rospy.Publisher] = ()) -> None:
        """In a releasing flush, send what is held for publishers with nothing new in it
        (but those in `written_next`, whose bytes follow: /clock)."""
        rest = self.held.release_rest(written_next)
        if rest:
            with self._holding:
                for pub, connection, data in rest:
                    if connection in pub.impl.connections:
                        self._send(pub, connection, data)

    def end_flush(self) -> None:
        """A flush has ended: the next byte held starts a new period."""
        self.held.end_flush()

    def _write(self, pub: rospy.Publisher, data: bytes | bytearray) -> None:
        if self.backlogs:
            self._forget_closed()
        held = self.held
        for connection in list(pub.impl.connections):
            out = data
            if held.subscribers and held.holds(connection):
                out = held.take(pub, connection, data)
                if out is None:
                    continue
            if not self._send(pub, connection, out):
                return

    def _send(self, pub: rospy.Publisher, connection: object,
              data: bytes | bytearray) -> bool:
        """Send `data` to one of `pub`'s connections, or drop it (it left or stalled);
        False once rospy has closed `pub` (nothing more to send to)."""
        backlogs = self.backlogs
        sock = getattr(connection, 'socket', None)
        try:
            if sock is None or connection.done:
                raise TransportTerminated('connection closed')
            if getattr(connection, 'transport_type', None) != 'TCPROS':
                if sock.gettimeout() is None:
                    sock.settimeout(SEND_TIMEOUT_S)
                sock.sendall(data)  # UDPROS: datagrams, never held by the subscriber
                return True
            backlog = backlogs.get(connection)
            if backlog is None:
                if sock.gettimeout() != 0.0:
                    sock.setblocking(False)
                try:
                    sent = sock.send(data)
                except BlockingIOError:
                    sent = 0
                if sent == len(data):
                    return True  # the hot path: everything taken at once
                backlog = backlogs[connection] = Backlog(memoryview(data)[sent:],
                                                         self.clock())
                patient = True  # a live subscriber whose buffer is full: wait a slice
            else:
                backlog.data += data
                patient = False  # stalled so far: wait only if it takes bytes again
            self._send_backlog(sock, backlog, patient)
            if not backlog.data:
                backlogs.pop(connection, None)  # back to normal
            elif len(backlog.data) > MAX_BACKLOG_BYTES:
                raise BacklogFull(f'more than {MAX_BACKLOG_BYTES} bytes not taken')
            elif self.clock() - backlog.progress_s >= SEND_TIMEOUT_S:
                raise TimeoutError(f'timed out: nothing taken for {SEND_TIMEOUT_S:g} s')
        except (TransportTerminated, OSError) as err:  # socket.timeout is an OSError
            return self._drop(pub, connection, err)
        return True

    def _drop(self, pub: rospy.Publisher, connection: object, err: Exception) -> bool:
        """Forget a connection that left or stalled; False once rospy has closed `pub`."""
        impl = pub.impl
        self.backlogs.pop(connection, None)
        self.held.forget(connection)
        if impl.closed:  # rospy closed every connection and cannot remove one any more
            return False
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
            # shutdown, such as a second atlas_sim registering): its listener list
            # is gone, and with it every connection. Nothing left to send to.
            if impl.closed:
                return False
            raise
        connection.close()
        return True

    def _send_backlog(self, sock: socket.socket, backlog: Backlog, patient: bool) -> None:
        """Send what `backlog` holds, in order. Without `patient`, give up at once unless
        the subscriber takes bytes; once it does (or with `patient`), wait for it slice by
        slice (STALL_PROBE_S) as long as it takes some within each slice."""
        data = backlog.data
        while data:
            try:
                sent = sock.send(data)
            except BlockingIOError:
                sent = 0
            if sent:
                del data[:sent]  # cheap: CPython drops a bytearray's head in place
                backlog.progress_s = self.clock()
                patient = True
                continue
            if not patient:
                return
            # Every byte not sent is in its backlog here: drain() may send them (see there).
            self._waiting = True
            ready = self.wait(sock, STALL_PROBE_S)
            self._waiting = False
            if not ready:
                return

    def _forget_closed(self) -> None:
        """Backlogs of connections rospy closed (subscriber gone): not kept in memory."""
        for connection in [c for c in self.backlogs if c.done or c.socket is None]:
            del self.backlogs[connection]

    def drain(self, timeout_s: float = SEND_TIMEOUT_S) -> None:
        """Send every backlog, waiting up to `timeout_s` in all: the rospy.on_shutdown hook.

        rospy's signal_shutdown runs client hooks, then closes every publisher connection:
        without this, what a live subscriber had not taken yet (the recorder's last joint
        states, stamped before a /clock value it already has) would be lost. On SIGINT the
        hook runs in the loop's own thread, between two bytecodes of whatever it was doing,
        possibly inside write(). Waiting for the lock there would deadlock, and a write
        interrupted between a send() and the bookkeeping of what it sent cannot be
        resumed by anyone else. So: the lock is taken without waiting; if write() holds it
        in this thread, the backlogs are drained only when it is inside its wait for a
        socket (every unsent byte is in its backlog then, and the write() then resumes on
        sockets that rospy has closed, and stops), else they are left (a rare, short
        window: the bytes of one send in progress). From another thread (a shutdown
        requested elsewhere), the lock is waited for.
        """
        if self.lock.acquire(blocking=False):
            try:
                self._drain(timeout_s)
            finally:
                self.lock.release()
        elif self._holder == threading.get_ident():
            if self._waiting:
                self._drain(timeout_s)
        elif self.lock.acquire(timeout=timeout_s):
            try:
                self._drain(timeout_s)
            finally:
                self.lock.release()

    def _drain(self, timeout_s: float) -> None:
        deadline_s = self.clock() + timeout_s
        for _pub, connection, data in self.held.pop_all():  # after any older backlog
            backlog = self.backlogs.get(connection)
            if backlog is None:
                self.backlogs[connection] = Backlog(data, self.clock())
            else:
                backlog.data += data
        for connection, backlog in list(self.backlogs.items()):
            sock, data = getattr(connection, 'socket', None), backlog.data
            try:
                while data and not connection.done and sock is not None:
                    try:
                        sent = sock.send(data)
                    except BlockingIOError:
                        sent = 0
                    if sent:
                        del data[:sent]
                        continue
                    remaining_s = deadline_s - self.clock()
                    if remaining_s <= 0.0 or not self.wait(sock, remaining_s):
                        break
            except OSError:
                pass  # the subscriber is gone: nothing to save
            if not data:
                self.backlogs.pop(connection, None)


def subscriber_names(pub: rospy.Publisher) -> set[str]:
    """The nodes connected to `pub` now.

    Count these, not get_num_connections(): when a subscriber connects twice at once
    (rospy does, on two quick publisher updates), the publisher holds both connections for a
    moment before dropping one, so a node counts twice and "the simulator and the recorder
    are connected" can be true with only the simulator.
    """
    return {connection.endpoint_id for connection in list(pub.impl.connections)}


class WireBatch:
    """Per-publisher byte batches, written on flush() with one send per connection.

    Replaced outlets (/clock: only its latest value goes out) are written after the
    batches, so a subscriber never gets a time before the messages stamped with it, even
    when the node stops in the middle of a flush. With a backlog (a subscriber that
    stalled, ConnectionWriter) this holds per connection: the recorder's /clock connection
    may be ahead of its joint states one until the backlog drains; drain() (an on_shutdown
    hook, sim_node.py) sends what is left when the node stops.
    """

    def __init__(self, writer: ConnectionWriter | None = None) -> None:
        self.writer = writer if writer is not None else ConnectionWriter()
        self.pending: dict[rospy.Publisher, bytearray] = {}
        self.latest: dict[rospy.Publisher, bytearray] = {}
        self.watchers: dict[rospy.Publisher, Callable[[bytearray], None]] = {}

    def watch(self, pub: rospy.Publisher, sent: Callable[[bytearray], None]) -> None:
        """Call `sent(data)` with what each flush has just written for `pub` (the node's
        own time follows the /clock it sends: node/own_clock.py)."""
        self.watchers[pub] = sent

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
        writer, watchers = self.writer, self.watchers
        write = writer.write
        writer.begin_flush()
        for batches in (pending, latest):
            for pub, data in batches.items():
                write(pub, data)
                if watchers:
                    sent = watchers.get(pub)
                    if sent is not None:
                        sent(data)
            if batches is pending:  # what is held goes out before the time (held_sends.py)
                writer.release_held(latest)
        writer.end_flush()

    def drain(self) -> None:
        """Send what stalled connections still hold (rospy.on_shutdown: see ConnectionWriter)."""
        self.writer.drain()
