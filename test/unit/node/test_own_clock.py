"""own_clock.py: the simulator's rospy time follows the /clock it sends, unsubscribed."""

from __future__ import annotations

import pytest
import rospy
from rospy.impl import simtime

from tutorial_atlas_control.msgs.wire import clock_bytes
from tutorial_atlas_control.node import own_clock
from tutorial_atlas_control.node.transport import ConnectionWriter, WireBatch


class Subscription:
    def __init__(self) -> None:
        self.unregistered = False

    def unregister(self) -> None:
        self.unregistered = True


class Writer(ConnectionWriter):
    def __init__(self) -> None:
        super().__init__()
        self.sent: list[tuple[str, bytes]] = []

    def write(self, pub: str, data: bytearray) -> None:
        self.sent.append((pub, bytes(data)))


@pytest.fixture
def sim_time(monkeypatch: pytest.MonkeyPatch) -> None:
    """rospy's time as under /use_sim_time, put back afterwards."""
    monkeypatch.setattr(rospy.rostime, '_rostime_current', rospy.Time(0, 0))
    monkeypatch.setattr(rospy.rostime, '_rostime_initialized', True)


def test_the_node_sets_its_time_from_each_clock_it_sends(
        monkeypatch: pytest.MonkeyPatch, sim_time: None) -> None:
    subscription = Subscription()
    monkeypatch.setattr(simtime, '_clock_sub', subscription, raising=False)
    writer = Writer()
    batch = WireBatch(writer)
    assert own_clock.follow_own_clock(batch, 'clock')
    assert subscription.unregistered and simtime._clock_sub is None
    batch.replace('clock', clock_bytes(12_345_000_000))
    batch.flush()
    assert writer.sent == [('clock', clock_bytes(12_345_000_000))]
    assert rospy.get_rostime() == rospy.Time(12, 345_000_000)
    batch.replace('clock', clock_bytes(3_000_000))  # a rewind (reset_simulation) too
    batch.flush()
    assert rospy.get_rostime() == rospy.Time(0, 3_000_000)


def test_time_is_the_last_clock_of_a_batch(sim_time: None) -> None:
    own_clock.set_rostime_from_clock(clock_bytes(1_000_000) + clock_bytes(2_500_000_000))
    assert rospy.get_rostime() == rospy.Time(2, 500_000_000)


def test_without_sim_time_nothing_changes(monkeypatch: pytest.MonkeyPatch,
                                          sim_time: None) -> None:
    monkeypatch.setattr(simtime, '_clock_sub', None, raising=False)
    batch = WireBatch(Writer())
    assert not own_clock.follow_own_clock(batch, 'clock')
    assert batch.watchers == {}
