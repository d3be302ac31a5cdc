"""recorder_watch.py: one line when the recorder goes (at once if killed); bag_dir's check."""

from __future__ import annotations

import threading
import time
from pathlib import Path
from types import SimpleNamespace

import pytest

from tutorial_atlas_control.bags.bag_dir import unwritable_reason

recorder_watch = pytest.importorskip('tutorial_atlas_control.node.recorder_watch',
                                     reason='needs the catkin workspace: source ./env.sh')
GRACE_S = recorder_watch.GRACE_S
stopped_line = recorder_watch.stopped_line

BOTH = {'/recorder', '/robot_state_publisher'}
OTHERS = {'/robot_state_publisher'}


def killed() -> bool:
    return True


def unregistered() -> bool:
    return False


def test_a_killed_recorder_is_reported_at_once_and_once() -> None:
    watch = recorder_watch.RecorderWatch()
    assert watch.update(BOTH, 0.0, 0.0, killed) is None
    line = watch.update(OTHERS, 10.0, 12.34, killed)
    assert line == stopped_line(12.34)
    assert line.startswith('the recorder (/recorder) stopped at sim time 12.3 s: this run is '
                           'no longer recorded (the simulation goes on)')
    assert watch.update(OTHERS, 100.0, 50.0, killed) is None, 'said once'


def test_a_recorder_that_unregistered_is_reported_only_after_grace_s() -> None:
    """Ctrl-C: roslaunch stops the simulator within the grace, and nothing is said."""
    watch = recorder_watch.RecorderWatch()
    watch.update(BOTH, 0.0, 0.0, unregistered)
    assert watch.update(OTHERS, 10.0, 12.34, unregistered) is None
    assert watch.update(OTHERS, 10.0 + GRACE_S / 2, 13.0, unregistered) is None
    assert watch.update(OTHERS, 10.0 + GRACE_S, 14.0, unregistered) == stopped_line(12.34)


def test_nothing_is_said_before_a_recorder_came_or_when_it_comes_back() -> None:
    watch = recorder_watch.RecorderWatch()
    assert watch.update(OTHERS, 0.0, 0.0, killed) is None, 'a launch with record:=false'
    watch.update(BOTH, 101.0, 1.0, unregistered)
    watch.update(OTHERS, 102.0, 2.0, unregistered)
    assert watch.update(BOTH, 102.5, 2.5, unregistered) is None, 'reconnected in the grace'
    assert watch.update(BOTH, 200.0, 100.0, unregistered) is None


class WatchedPublisher:
    """What start_recorder_watch reads of a rospy.Publisher: impl.connections."""

    def __init__(self, *nodes: str) -> None:
        self.impl = SimpleNamespace(connections=[SimpleNamespace(endpoint_id=node)
                                                 for node in nodes])

    def disconnect(self, node: str) -> None:
        self.impl.connections = [c for c in self.impl.connections if c.endpoint_id != node]


def watch_thread(shutting_down: threading.Event) -> tuple[WatchedPublisher, list[str],
                                                          threading.Event, threading.Thread]:
    """A watch over a publisher both nodes read, the master still listing the recorder.
    Returns the publisher, the lines said, the watch's stop event and its thread."""
    before = set(threading.enumerate())
    publisher, said, polled = WatchedPublisher(*BOTH), [], threading.Event()

    def sim_s() -> float:  # read at each poll
        polled.set()
        return 4.5

    stop = recorder_watch.start_recorder_watch(publisher, sim_s, time.monotonic,
                                               lambda: True, shutting_down.is_set,
                                               said.append, 0.01)
    thread, = (t for t in set(threading.enumerate()) - before if t.name == 'recorder_watch')
    assert polled.wait(5.0), 'the recorder was seen'
    return publisher, said, stop, thread


def test_a_recorder_gone_while_the_simulator_runs_is_said_by_the_thread() -> None:
    publisher, said, stop, _ = watch_thread(threading.Event())
    try:
        publisher.disconnect('/recorder')
        deadline = time.monotonic() + 5.0
        while not said and time.monotonic() < deadline:
            time.sleep(0.01)
        assert said == [stopped_line(4.5)]
    finally:
        stop.set()


def test_the_watch_ends_when_the_simulators_own_shutdown_begins() -> None:
    """Ctrl-C: the simulator unregisters its publishers before rospy.is_shutdown() turns
    True; the master tells the recorder, which drops its connection while still listed,
    as a killed recorder would be: nothing may be said from then on."""
    shutting_down = threading.Event()
    publisher, said, stop, thread = watch_thread(shutting_down)
    try:
        shutting_down.set()
        thread.join(5.0)
        publisher.disconnect('/recorder')
        assert not thread.is_alive(), 'the watch goes on in a node shutting down'
        assert said == []
    finally:
        stop.set()


def test_shutdown_begins_with_rospy_s_request(monkeypatch: pytest.MonkeyPatch) -> None:
    """Requested (shutdown hooks running), not only done: rospy.is_shutdown() is still False
    while they unregister the node's topics."""
    import rospy

    assert not recorder_watch._shutting_down()
    monkeypatch.setattr(rospy.core, '_in_shutdown', True)
    assert not rospy.is_shutdown()
    assert recorder_watch._shutting_down()


def test_bag_dir_check_creates_the_directory_and_names_the_reason(tmp_path: Path) -> None:
    assert unwritable_reason(tmp_path / 'new' / 'bags') is None
    assert (tmp_path / 'new' / 'bags').is_dir()
    assert list((tmp_path / 'new' / 'bags').iterdir()) == [], 'the probe file is removed'
    blocker = tmp_path / 'a_file'
    blocker.write_text('')
    assert unwritable_reason(blocker / 'bags') == 'Not a directory'
