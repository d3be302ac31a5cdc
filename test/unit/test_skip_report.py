"""test/conftest.py's skip report: a skip is named loudly in a local run and fails a CI run.

Each case runs pytest in a subprocess on a one-test file in tmp_path with test/conftest.py
loaded as a plugin, as `make test` loads it for the tree.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from support.pytest_runs import run_pytest

SKIPPING = 'import pytest\n\n\ndef test_needs_a_tool():\n    pytest.skip("no such tool")\n'
OPTIONAL = ('import pytest\n\n\n@pytest.mark.optional\ndef test_needs_reference_files():\n'
            '    pytest.skip("no reference files")\n')


def test_a_local_run_names_its_skips_loudly(tmp_path: Path) -> None:
    result = run_pytest(tmp_path, SKIPPING, '')
    assert result.returncode == 0, result.stdout
    assert ('SKIPPED, WHICH TAC_REQUIRE_ALL=1 (CI) WOULD FAIL: 1 test(s): '
            'test_sample.py::test_needs_a_tool (no such tool)') in result.stdout


def test_a_ci_run_fails_on_a_skip(tmp_path: Path) -> None:
    result = run_pytest(tmp_path, SKIPPING, '1')
    assert result.returncode == pytest.ExitCode.TESTS_FAILED, result.stdout
    assert ('TAC_REQUIRE_ALL=1: 1 test(s) skipped, which fails the run: '
            'test_sample.py::test_needs_a_tool (no such tool)') in result.stdout


def test_an_optional_skip_is_allowed_in_ci_and_quiet_locally(tmp_path: Path) -> None:
    ci = run_pytest(tmp_path, OPTIONAL, '1')
    assert ci.returncode == 0, ci.stdout
    assert 'TAC_REQUIRE_ALL: 1 optional test(s) skipped, allowed' in ci.stdout
    local = run_pytest(tmp_path, OPTIONAL, '')
    assert local.returncode == 0 and 'WOULD FAIL' not in local.stdout, local.stdout
