"""The test files pytest collects have distinct names.

pytest imports test modules by basename (no __init__.py in the test folders): two files
called test_stepping.py, one in test/unit and one in test/integration, stop the whole run
at collection ("import file mismatch"), as a fresh clone showed once.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path

TEST_DIR = Path(__file__).resolve().parent.parent
#: The folders `make test` gives pytest (the rostests' files are run by rostest).
COLLECTED = ('unit', 'integration', 'reliability')


def test_collected_test_files_have_distinct_names() -> None:
    names = Counter(path.name for folder in COLLECTED
                    for path in (TEST_DIR / folder).rglob('test_*.py'))
    assert sum(names.values()) > 50, 'the test folders were not found'
    twice = sorted(name for name, count in names.items() if count > 1)
    assert not twice, f'test files with the same name in {COLLECTED}: {twice}'
