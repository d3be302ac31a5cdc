"""The scripts' entry: their main() imported only once the environment is known to hold it.

Run from a shell without `source ./env.sh`, a script finds the package (its wrapper puts
src/ on the path) but not the virtualenv's modules (rosbags, mujoco, ...) nor the
workspace's messages: an import error then says so in one line instead of a traceback,
even for --help. traj_yaml.py says the same in its own words (trajectories/traj_yaml_node.py).

The modules load with SIGINT blocked, so that the threads their C libraries start meanwhile
(numpy's OpenBLAS worker) never take a Ctrl-C: Python (3.11, POSIX) handles a signal only
when the thread that received it was its main thread or a later GIL hand-off says so, and a
script whose only Python thread is busy simulating then ignored Ctrl-C for good.
"""

from __future__ import annotations

import importlib
import os
import signal
import sys

from tutorial_atlas_control.cli.convention import EXIT_REFUSED, print_error

__all__ = ['ENV_HINT', 'EXIT_BROKEN_PIPE', 'run_script']

PACKAGE = 'tutorial_atlas_control'
#: Exit status when stdout's reader went away: 128 + SIGPIPE, as a shell reports it.
EXIT_BROKEN_PIPE = 141
#: What a shell needs before running the scripts.
ENV_HINT = 'run `source ./env.sh` in the repository first (after `make setup`)'


def run_script(prog: str, module: str) -> int:
    """Import `module` and return its main()'s exit status.

    A module missing from the environment (not one of the package's own, which would be
    a bug and keeps its traceback): one stderr line naming it, exit status 1.
    """
    try:
        main = _import_without_ctrl_c(module).main
    except ModuleNotFoundError as err:
        missing = err.name or str(err)
        if missing.split('.')[0] == PACKAGE:
            raise
        print_error(prog, f'cannot import {missing}: this shell lacks the project\'s '
                          f'environment; {ENV_HINT}')
        return EXIT_REFUSED
    try:
        return main()
    except BrokenPipeError:
        # Output piped into `head` and the like: the reader left, which is no error. stdout
        # goes to /dev/null so that the interpreter's final flush does not raise again.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_BROKEN_PIPE


def _import_without_ctrl_c(module: str) -> object:
    """importlib.import_module(`module`), SIGINT blocked meanwhile: threads started during
    the import inherit the block; the main thread gets its mask back (a Ctrl-C that came
    meanwhile is delivered then)."""
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        return importlib.import_module(module)
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)
