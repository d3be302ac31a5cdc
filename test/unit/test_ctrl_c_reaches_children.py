"""test/conftest.py: a test's child gets Ctrl-C even when pytest was started as a
non-interactive shell's background job (make test's parts, a CI runner), with SIGINT ignored.

An ignored signal stays ignored across exec: without the conftest's handler a child of the
tests ignores the SIGINT stop_tree sends, and is killed 20 s later (a plot test's teardown
took 22 s in every make test run).
"""

from __future__ import annotations

import signal
from pathlib import Path

from support.pytest_runs import run_pytest

#: A test that starts a Python child and asserts it would take Ctrl-C as KeyboardInterrupt.
CHILD_DISPOSITION = '''import subprocess, sys


def test_a_child_takes_ctrl_c():
    shown = subprocess.run(
        [sys.executable, '-c', 'import signal; print(signal.getsignal(signal.SIGINT))'],
        capture_output=True, text=True, check=True).stdout.strip()
    assert shown == '<built-in function default_int_handler>', shown
'''


def ignore_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def test_a_child_of_a_backgrounded_pytest_takes_ctrl_c(tmp_path: Path) -> None:
    result = run_pytest(tmp_path, CHILD_DISPOSITION, preexec_fn=ignore_sigint)
    assert result.returncode == 0, result.stdout + result.stderr
    assert '1 passed' in result.stdout
