"""test/conftest.py's test order: live tests first, unit tests last (support/ordering.py).

The wiring is checked as test_skip_report.py checks its own: pytest in a subprocess on a
small tree in tmp_path, with test/conftest.py loaded as a plugin.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from support.ordering import is_unit_test, live_tests_first

TEST_DIR = Path(__file__).resolve().parents[1]
#: Guard (s) against a hung pytest.
PYTEST_GUARD_S = 120.0
TWO_TESTS = 'def test_one():\n    pass\n\n\ndef test_two():\n    pass\n'


class Item:
    def __init__(self, path: str) -> None:
        self.path = Path(path)


def test_unit_tests_go_last_and_each_group_keeps_its_order() -> None:
    items = [Item(p) for p in ('/r/test/unit/a/test_x.py', '/r/test/unit/test_y.py',
                               '/r/test/integration/test_z.py', '/r/test/unit/test_w.py',
                               '/r/test/reliability/test_v.py')]
    live_tests_first(items)
    assert [str(item.path) for item in items] == [
        '/r/test/integration/test_z.py', '/r/test/reliability/test_v.py',
        '/r/test/unit/a/test_x.py', '/r/test/unit/test_y.py', '/r/test/unit/test_w.py']


def test_only_a_unit_directory_of_test_counts() -> None:
    assert is_unit_test(Item('/r/test/unit/test_x.py'))
    assert not is_unit_test(Item('/r/unit/test_x.py'))
    assert not is_unit_test(Item('/r/test/integration/test_unit.py'))


def test_pytest_collects_the_live_tests_first(tmp_path: Path) -> None:
    for folder in ('unit', 'integration'):
        (tmp_path / 'test' / folder).mkdir(parents=True)
        (tmp_path / 'test' / folder / f'test_{folder}_sample.py').write_text(TWO_TESTS)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [
        str(TEST_DIR), os.environ.get('PYTHONPATH')])))
    result = subprocess.run([sys.executable, '-m', 'pytest', '-p', 'conftest', '-q',
                             '--collect-only', '-p', 'no:cacheprovider', '--rootdir',
                             str(tmp_path), 'test/unit', 'test/integration'],
                            cwd=tmp_path, env=env, capture_output=True, text=True,
                            timeout=PYTEST_GUARD_S, check=False)
    assert result.returncode == 0, result.stdout + result.stderr
    ids = [line for line in result.stdout.splitlines() if '::' in line]
    assert ids == ['test/integration/test_integration_sample.py::test_one',
                   'test/integration/test_integration_sample.py::test_two',
                   'test/unit/test_unit_sample.py::test_one',
                   'test/unit/test_unit_sample.py::test_two']
