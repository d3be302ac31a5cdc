"""recorder_watch.py: one line when the recorder goes (at once if killed); bag_dir's check."""

from __future__ import annotations

from pathlib import Path

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


def test_bag_dir_check_creates_the_directory_and_names_the_reason(tmp_path: Path) -> None:
    assert unwritable_reason(tmp_path / 'new' / 'bags') is None
    assert (tmp_path / 'new' / 'bags').is_dir()
    assert list((tmp_path / 'new' / 'bags').iterdir()) == [], 'the probe file is removed'
    blocker = tmp_path / 'a_file'
    blocker.write_text('')
    assert unwritable_reason(blocker / 'bags') == 'Not a directory'
