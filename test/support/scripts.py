"""Running the package's scripts as a user does after `source ./env.sh`."""

from __future__ import annotations

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


#: Wall-clock guard (s) for an interrupted script to get going (a Dask cluster starting, its
#: first runs finishing) on a loaded machine.
READY_TIMEOUT_S = 180.0


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
            processes.wait_until(lambda: ready(err_path.read_text()), READY_TIMEOUT_S,
                                 f'{name} did not get ready to be interrupted',
                                 lambda: _still_running(process, err_path))
        finally:
            clean = processes.stop_tree(process)
    result = subprocess.CompletedProcess(process.args, process.returncode,
                                         out_path.read_text(), err_path.read_text())
    out_path.unlink()
    err_path.unlink()
    assert clean, f'{name} did not end on SIGINT: {result}'
    return result


def _still_running(process: subprocess.Popen, err_path: Path) -> None:
    if process.poll() is not None:
        raise processes.ProcessError(f'it ended first ({process.returncode}): '
                                     f'{err_path.read_text()}')
