"""Fixtures shared by the unit tests."""

from __future__ import annotations

import ctypes

import pytest

from tutorial_atlas_control import native


@pytest.fixture(scope='module')
def library() -> ctypes.CDLL:
    """The compiled library of the catkin workspace (the law and the message copies)."""
    library = native.load_library()
    assert library is not None, (f'{native.LIBRARY_NAME} is not in the catkin workspace: '
                                 'run `make setup` and `source ./env.sh`')
    return library
