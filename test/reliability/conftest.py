"""The reliability tests' fixture: one atlas.launch per test (see support.launch)."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from support.launch import TestLaunch


@pytest.fixture()
def atlas_launch(tmp_path: Path, request: pytest.FixtureRequest) -> Iterator[TestLaunch]:
    """Start atlas.launch with the test's launch args (`@pytest.mark.launch_args(...)`)."""
    pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')
    marker = request.node.get_closest_marker('launch_args')
    with TestLaunch(tmp_path, *(marker.args if marker else ())) as launch:
        yield launch


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line('markers', 'launch_args(*args): roslaunch arguments of the test')
