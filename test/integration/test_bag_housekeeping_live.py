"""atlas.launch's bag housekeeping, live: keep_bags:= reaches the recorder's start (through
roslaunch's <env>), which says what bag_dir holds and deletes the oldest bags. About 20 s."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from support.launch import EXIT_TIMEOUT_S, TestLaunch

MB = 1_000_000


def test_keep_bags_deletes_the_oldest_as_the_launch_starts(tmp_path: Path) -> None:
    bag_dir = tmp_path / 'bags'
    bag_dir.mkdir()
    old = [bag_dir / f'atlas_2020-01-01-00-00-0{k}.bag' for k in range(3)]
    for index, path in enumerate(old):
        with path.open('wb') as stream:
            stream.truncate(5 * MB)
        os.utime(path, (1_000_000 + index,) * 2)
    with TestLaunch(tmp_path, 'keep_bags:=2') as launch:
        launch.wait_ready()
        launch.interrupt(EXIT_TIMEOUT_S)
        output = launch.output()
    assert f'record_run.sh: bag directory {bag_dir}: 3 bags, 15 MB\n' in output, output
    assert (f'record_run.sh: deleted 2 old bags (10 MB) in {bag_dir} to keep keep_bags=2, '
            "max_bags_mb=4000 (counting this run's)") in output, output
    left = sorted(path.name for path in bag_dir.iterdir())
    assert len(left) == 2 and left[0] == old[2].name, left  # the newest old one, and the run's
    assert left[1] not in {path.name for path in old}, left
