"""Fixtures shared by the unit tests."""

from __future__ import annotations

import ctypes
from pathlib import Path

import pytest

from tutorial_atlas_control import native

UNIT_DIR = Path(__file__).resolve().parent


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Every unit test is `offline` (pytest.ini): ROS-free and with no claim about time, so
    `make test` runs them at the lowest priority beside the serial tests."""
    for item in items:
        if UNIT_DIR in item.path.parents:
            item.add_marker(pytest.mark.offline)


@pytest.fixture(scope='module')
def library() -> ctypes.CDLL:
    """The compiled library of the catkin workspace (the law and the message copies)."""
    library = native.load_library()
    assert library is not None, (f'{native.LIBRARY_NAME} is not in the catkin workspace: '
                                 'run `make setup` and `source ./env.sh`')
    return library
