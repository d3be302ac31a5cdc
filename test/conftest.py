"""Skips that hide gaps: with TAC_REQUIRE_ALL=1 (CI sets it, .ci/run) any skip fails the run.

A skip says a test did not check its claim. On a machine set up by `make setup` every test
can run, so under TAC_REQUIRE_ALL=1 a skip means a broken workspace or a missing tool, and
the run ends with one line naming the skipped tests and exit status 1. Without it (a local
`make test`) the run ends with one loud line naming them too, so that a green local run
never hides what CI would fail on. Only tests marked
`@pytest.mark.optional(reason)` may skip there: they need something no clone carries (the
DRCSim reference files beside the repository); their skips are listed, and allowed.

Also: make test's two xdist workers take whole modules (support/xdist_scheduling.py), so
that a module-scoped launch starts once. And Ctrl-C reaches the tests' children. A
non-interactive shell starts its background jobs (make test's, a CI runner's) with SIGINT
ignored, an ignored signal stays ignored across exec, and the tests stop their children
with SIGINT as a terminal would.
"""

from __future__ import annotations

import os
import signal
import threading

import pytest

#: The environment variable that turns skips into a failed run.
REQUIRE_ALL_ENV = 'TAC_REQUIRE_ALL'
OPTIONAL_MARKER = 'optional'

_unexpected: list[str] = []
_optional: list[str] = []


def require_all() -> bool:
    return os.environ.get(REQUIRE_ALL_ENV, '') not in ('', '0')


def ctrl_c_as_in_a_terminal() -> None:
    """Python's SIGINT handler, SIGINT unblocked, in this process's main thread: each child
    then starts with SIGINT at its default action (exec resets handled signals only). Without
    it a started child ignores the SIGINT that stop_tree sends, and is killed 20 s later."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def pytest_configure(config: pytest.Config) -> None:
    ctrl_c_as_in_a_terminal()
    config.addinivalue_line(
        'markers', f'{OPTIONAL_MARKER}(reason): may skip even with {REQUIRE_ALL_ENV}=1 '
                   '(it needs files no clone carries)')


def _skip_reason(report: pytest.TestReport | pytest.CollectReport) -> str:
    longrepr = report.longrepr
    if isinstance(longrepr, tuple) and len(longrepr) == 3:
        return str(longrepr[2]).removeprefix('Skipped: ')
    return str(longrepr)


def _note(report: pytest.TestReport | pytest.CollectReport, optional: bool) -> None:
    entry = f'{report.nodeid} ({_skip_reason(report)})'
    (_optional if optional else _unexpected).append(entry)


def pytest_runtest_logreport(report: pytest.TestReport) -> None:
    if report.skipped and not hasattr(report, 'wasxfail'):
        _note(report, OPTIONAL_MARKER in report.keywords)


def pytest_collectreport(report: pytest.CollectReport) -> None:
    if report.skipped:  # a module-level skip (importorskip): never optional
        _note(report, False)


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    if require_all() and _unexpected and exitstatus in (pytest.ExitCode.OK,
                                                    pytest.ExitCode.NO_TESTS_COLLECTED):
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter) -> None:
    if not require_all():
        if _unexpected:
            terminalreporter.write_line(
                f'SKIPPED, WHICH {REQUIRE_ALL_ENV}=1 (CI) WOULD FAIL: {len(_unexpected)} '
                'test(s): ' + '; '.join(_unexpected), red=True, bold=True)
        return
    if _optional:
        terminalreporter.write_line(
            f'{REQUIRE_ALL_ENV}: {len(_optional)} optional test(s) skipped, allowed: '
            + '; '.join(_optional))
    if _unexpected:
        terminalreporter.write_line(
            f'{REQUIRE_ALL_ENV}=1: {len(_unexpected)} test(s) skipped, which fails the run: '
            + '; '.join(_unexpected), red=True, bold=True)


def pytest_xdist_make_scheduler(config: pytest.Config, log: object) -> object:
    """Whole modules to a worker (support/xdist_scheduling.py); `-n` without `--dist` too."""
    from support.xdist_scheduling import ModuleScheduling

    return ModuleScheduling(config, log)
