"""pytest in a subprocess on a one-test file, with test/conftest.py loaded as a plugin, as
`make test` loads it for the tree: for the tests of that conftest's hooks."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

TEST_DIR = Path(__file__).resolve().parents[1]
#: Guard (s) against a hung pytest.
PYTEST_GUARD_S = 120.0


def run_pytest(tmp_path: Path, source: str, require_all: str = '',
               preexec_fn: Callable[[], None] | None = None) -> subprocess.CompletedProcess:
    """pytest -q on `source` written to tmp_path/test_sample.py; TAC_REQUIRE_ALL=`require_all`.

    `preexec_fn` runs in the child before pytest starts (e.g. to ignore SIGINT, as a shell
    starts a background job).
    """
    (tmp_path / 'test_sample.py').write_text(source, encoding='utf-8')
    env = dict(os.environ, TAC_REQUIRE_ALL=require_all,
               PYTHONPATH=os.pathsep.join(filter(None, [str(TEST_DIR),
                                                        os.environ.get('PYTHONPATH')])))
    return subprocess.run([sys.executable, '-m', 'pytest', '-p', 'conftest', '-q',
                           '-p', 'no:cacheprovider', '--rootdir', str(tmp_path),
                           str(tmp_path / 'test_sample.py')],
                          cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=PYTEST_GUARD_S, check=False, preexec_fn=preexec_fn)
