"""The order pytest hands the tests to its xdist workers: live tests first, unit tests last.

xdist's load scheduler hands tests out in collection order, as the workers ask for more. The
last tests decide how long one worker runs alone once the other has nothing left: a live
test (up to a minute) at the end can leave a core idle that long, a unit test (milliseconds)
cannot. Collected as they are (test/unit before test/integration), the live tests came last.
"""

from __future__ import annotations

from collections.abc import MutableSequence
from pathlib import Path
from typing import Protocol

__all__ = ['is_unit_test', 'live_tests_first']


class _Item(Protocol):
    path: Path


def is_unit_test(item: _Item) -> bool:
    """Is `item` under a test/unit directory?"""
    parts = item.path.parts
    return any(a == 'test' and b == 'unit' for a, b in zip(parts, parts[1:]))


def live_tests_first(items: MutableSequence[_Item]) -> None:
    """Put the unit tests after the others, each group in its own order (modules stay whole,
    so a module's fixtures are set up once per worker, as before)."""
    items[:] = sorted(items, key=is_unit_test)
