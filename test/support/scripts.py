"""Running the package's scripts as a user does after `source ./env.sh`."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

from tutorial_atlas_control import processes

SCRIPTS = Path(__file__).resolve().parents[2] / 'scripts'
#: Wall-clock guard (s) against a hang; the offline searches and sweeps take a minute or so.
SCRIPT_TIMEOUT_S = 600.0


def run_script(name: str, *args: str,
               timeout_s: float = SCRIPT_TIMEOUT_S) -> subprocess.CompletedProcess[str]:
    """scripts/`name` with `args`: exit code, stdout and stderr captured as text."""
    return subprocess.run([sys.executable, str(SCRIPTS / name), *args], capture_output=True,
                          text=True, timeout=timeout_s, check=False)


#: Guard against a script that never gets ready to be interrupted (a Dask cluster starting,
#: its first runs finishing), in CPU seconds of the script's process tree, not wall seconds:
#: `make test` runs these tests at the lowest priority, where a script can wait minutes for a
#: core (a search starved beside the live tests had not logged its two generations after 180
#: wall seconds, 2026-11-29).
READY_CPU_S = 180.0
#: Wall-clock guard (s) against a hang that uses no CPU (a deadlock, a lost worker).
READY_WALL_S = 1800.0
#: After the Ctrl-C, the script's tree may spend this many CPU seconds ending (its Dask
#: cluster's teardown), in at most STOP_WALL_S: at the lowest priority a search's cluster took
#: over processes.STOP_TIMEOUT_S's 20 wall seconds to end, its "interrupted" line already
#: written (fresh clone, 2026-11-29).
STOP_CPU_S = 60.0
STOP_WALL_S = 600.0


def interrupt_script(name: str, *args: str, ready: Callable[[str], bool],
                     cwd: Path) -> subprocess.CompletedProcess[str]:
    """scripts/`name` in `cwd`, Ctrl-C'd (SIGINT to its process group, as a terminal sends
    it, workers included) once `ready(its stderr so far)` holds; its outcome, as run_script's.

    Fails the test if it ends before it was ready or does not end on the signal.
    """
    out_path, err_path = cwd / f'.{name}.stdout', cwd / f'.{name}.stderr'
    with out_path.open('w') as out, err_path.open('w') as err:
        process = subprocess.Popen([sys.executable, str(SCRIPTS / name), *args], cwd=cwd,
                                   stdout=out, stderr=err, text=True, start_new_session=True,
                                   preexec_fn=processes.default_sigint)
        try:
            processes.wait_until(lambda: ready(err_path.read_text()), READY_WALL_S,
                                 f'{name} did not get ready to be interrupted',
                                 lambda: _still_working(process, err_path))
            with contextlib.suppress(ProcessLookupError):  # Ctrl-C, to its workers too
                os.killpg(process.pid, signal.SIGINT)
            spent_s = tree_cpu_seconds(process.pid)
            processes.wait_until(lambda: process.poll() is not None, STOP_WALL_S,
                                 f'{name} did not end on SIGINT',
                                 lambda: _still_stopping(process, spent_s, err_path))
        finally:
            clean = processes.stop_tree(process)
    result = subprocess.CompletedProcess(process.args, process.returncode,
                                         out_path.read_text(), err_path.read_text())
    out_path.unlink()
    err_path.unlink()
    assert clean, f'{name} did not end on SIGINT: {result}'
    return result


def _still_working(process: subprocess.Popen, err_path: Path) -> None:
    """Raise if the script ended, or its process tree spent READY_CPU_S without getting
    ready."""
    if process.poll() is not None:
        raise processes.ProcessError(f'it ended first ({process.returncode}): '
                                     f'{err_path.read_text()}')
    spent = tree_cpu_seconds(process.pid)
    if spent > READY_CPU_S:
        raise processes.ProcessError(f'it spent {spent:.0f} CPU s without getting ready: '
                                     f'{err_path.read_text()}')


def _still_stopping(process: subprocess.Popen, spent_s: float, err_path: Path) -> None:
    """Raise if the script's tree spent STOP_CPU_S since the Ctrl-C without ending."""
    ending_s = tree_cpu_seconds(process.pid) - spent_s
    if process.poll() is None and ending_s > STOP_CPU_S:
        raise processes.ProcessError(f'it spent {ending_s:.0f} CPU s after SIGINT without '
                                     f'ending: {err_path.read_text()}')


def tree_cpu_seconds(pid: int) -> float:
    """CPU time (s) of `pid` and its live descendants, with the children each has reaped."""
    return sum(processes.cpu_seconds(each, reaped_children=True)
               for each in (pid, *processes.descendants(pid)))
