"""held_sends.py and its use by transport.py: the recorder's bytes every few ms, in order,
every other subscriber's at each flush, nothing lost at shutdown."""

from __future__ import annotations

import pytest
from test_transport import Clock, FakePublisher, TcpConnection, Waits

from tutorial_atlas_control.node import transport
from tutorial_atlas_control.node.held_sends import HeldSends

PERIOD_S = 0.01  # a test's own, not the default


class Named:
    def __init__(self, name: str) -> None:
        self.endpoint_id = name


def held_writer(clock: Clock, period_s: float = PERIOD_S) -> transport.ConnectionWriter:
    return transport.ConnectionWriter(clock, Waits(clock),
                                      HeldSends({'/recorder'}, period_s, clock))


def run_steps(batch: transport.WireBatch, clock: Clock, pubs: dict, steps: range) -> None:
    """One flush a millisecond, as the loop at real time: a state, an odometry every
    fifth step (a topic with nothing new in most flushes), then the time."""
    for step in steps:
        batch.add(pubs['state'], b'S%d;' % step)
        if step % 5 == 0:
            batch.add(pubs['odom'], b'O%d;' % step)
        batch.replace(pubs['clock'], b'C%d;' % step)
        batch.flush()
        clock.now_s += 0.001


def test_only_the_named_subscribers_are_held_and_a_hold_cannot_be_negative() -> None:
    held = HeldSends({'/recorder'}, PERIOD_S)
    assert held.holds(Named('/recorder')) and not held.holds(Named('/traj_yaml'))
    assert not HeldSends({'/recorder'}, 0.0).holds(Named('/recorder')), '0 holds nothing'
    for bad in (-0.01, float('nan')):
        with pytest.raises(ValueError, match='the hold must be a number of seconds >= 0'):
            HeldSends({'/recorder'}, bad)


def test_the_recorder_gets_one_send_per_topic_a_period_a_client_one_each_flush() -> None:
    clock = Clock()
    batch = transport.WireBatch(held_writer(clock))
    recorder = {name: TcpConnection('/recorder') for name in ('state', 'odom', 'clock')}
    client = {name: TcpConnection('/traj_yaml') for name in ('state', 'odom', 'clock')}
    pubs = {name: FakePublisher([recorder[name], client[name]]) for name in recorder}
    run_steps(batch, clock, pubs, range(1, 31))

    every = {'state': b''.join(b'S%d;' % s for s in range(1, 31)),
             'odom': b''.join(b'O%d;' % s for s in range(5, 31, 5)),
             'clock': b''.join(b'C%d;' % s for s in range(1, 31))}
    for name in every:  # the client: everything, one send per flush that had some
        assert bytes(client[name].socket.in_buffer) == every[name]
    assert client['state'].socket.send_calls == 30
    # The recorder: held from step 1; the flush 10 ms later (step 11) releases steps 1-11,
    # the next hold starts at step 12 and goes out at step 22; 23-30 are still held.
    assert recorder['state'].socket.send_calls == 2
    for name, first_held in (('state', b'S23;'), ('clock', b'C23;')):
        sent = every[name][:every[name].index(first_held)]
        assert bytes(recorder[name].socket.in_buffer) == sent
    # odom had nothing new at step 11: its held bytes went out in that flush all the same.
    assert bytes(recorder['odom'].socket.in_buffer) == b'O5;O10;O15;O20;'
    assert recorder['odom'].socket.send_calls == 2


def test_in_a_releasing_flush_the_time_goes_after_the_messages_stamped_with_it() -> None:
    clock = Clock()
    order: list[bytes] = []

    class Recording(TcpConnection):
        def __init__(self) -> None:
            super().__init__('/recorder')
            send = self.socket.send

            def logged(data):
                order.append(bytes(data))
                return send(data)
            self.socket.send = logged

    pubs = {name: FakePublisher([Recording()]) for name in ('state', 'odom', 'clock')}
    run_steps(transport.WireBatch(held_writer(clock)), clock, pubs, range(1, 12))
    assert order == [b''.join(b'S%d;' % s for s in range(1, 12)), b'O5;O10;',
                     b''.join(b'C%d;' % s for s in range(1, 12))]


def test_what_is_held_at_shutdown_is_drained_after_older_backlog() -> None:
    clock = Clock()
    writer = held_writer(clock)
    recorder = TcpConnection('/recorder', space=4)  # takes 4 bytes, then nothing until read
    pub = FakePublisher([recorder])
    batch = transport.WireBatch(writer)
    batch.add(pub, b'AAAAAA')
    batch.flush()  # held
    clock.now_s += PERIOD_S  # the next flush releases: 4 bytes go, 'AA' + 'BB' backlogged
    batch.add(pub, b'BB')
    batch.flush()
    assert bytes(recorder.socket.in_buffer) == b'AAAA'
    batch.add(pub, b'CC')  # held: a new period began
    batch.flush()
    recorder.socket.reads_per_slice = 100
    writer.drain(timeout_s=1.0)
    assert bytes(recorder.socket.received + recorder.socket.in_buffer) == b'AAAAAABBCC'
    assert writer.held.held == {} and writer.backlogs == {}


def test_a_recorder_that_left_has_nothing_held_for_it() -> None:
    clock = Clock()
    writer = held_writer(clock)
    recorder, client = TcpConnection('/recorder'), TcpConnection('/client')
    pub = FakePublisher([recorder, client])
    batch = transport.WireBatch(writer)
    batch.add(pub, b'x' * 100)
    batch.flush()
    assert recorder in writer.held.held
    pub.connections.remove(recorder)  # rospy dropped it (the recorder exited)
    recorder.close()
    clock.now_s += PERIOD_S
    batch.flush()  # a releasing flush with nothing new: the held bytes have nowhere to go
    assert writer.held.held == {} and recorder.socket.send_calls == 0
    assert bytes(client.socket.in_buffer) == b'x' * 100
