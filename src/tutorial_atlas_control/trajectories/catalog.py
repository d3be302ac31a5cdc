"""The package's trajectory files as one catalogue: which file holds a trajectory name, and
which gains a trajectory file needs (`make demo TRAJ=<name>`, run_demo.py).

A name is looked up in every ``trajectories/*.yaml``, the tutorial's ``Traj_data2.yaml``
first; it must be in exactly one of them, so that adding a file never silently changes what
an existing name plays.

A trajectory file may have *companion gains*: ``<its directory>/../config/<stem in lower
case>_gains.yaml``, e.g. ``trajectories/Stepping.yaml`` -> ``config/stepping_gains.yaml``
(a step that only stands with stiffer legs). A file without one plays with the tutorial's
gains, ``config/atlas_controller.yaml`` (atlas.launch's default).
"""

from __future__ import annotations

import difflib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from tutorial_atlas_control.sim import DEFAULT_GAINS_FILE
from tutorial_atlas_control.trajectories.trajectory import (
    TRAJECTORIES_DIR,
    TrajectoryError,
    load_trajectory_file,
)

__all__ = ['TUTORIAL_FILE_NAME', 'GainsChoice', 'companion_gains_file', 'find_trajectory',
           'gains_for', 'trajectory_files']

#: The tutorial's file: searched first, listed first.
TUTORIAL_FILE_NAME = 'Traj_data2.yaml'
#: A companion gains file's name: the trajectory file's stem in lower case, then this.
GAINS_SUFFIX = '_gains.yaml'


def trajectory_files(directory: Path = TRAJECTORIES_DIR) -> list[Path]:
    """The ``*.yaml`` files of `directory`: the tutorial's first, the others by name."""
    files = sorted(path for path in directory.glob('*.yaml') if path.is_file())
    return sorted(files, key=lambda path: path.name != TUTORIAL_FILE_NAME)


def find_trajectory(name: str, directory: Path = TRAJECTORIES_DIR,
                    walks: Sequence[str] = ()) -> Path:
    """The one file of `directory` (see :func:`trajectory_files`) that holds trajectory `name`.

    `walks`: the other names the caller takes (run_demo.py's walks), listed and suggested
    beside the trajectories when `name` is none of them.

    Raises:
        TrajectoryError: no file, or more than one, holds `name` (one line listing the files
            searched and, for a name close to a valid one, "did you mean"), or a file cannot
            be read (its own one-line error).
    """
    files = trajectory_files(directory)
    docs = {path: load_trajectory_file(path) for path in files}
    holding = [path for path in files if name in docs[path]]
    if len(holding) == 1:
        return holding[0]
    searched = ', '.join(str(path) for path in files) or f'no *.yaml in {directory}'
    if not holding:
        names = '; '.join(f'{path.name}: ' + ', '.join(str(key) for key in docs[path])
                          for path in files) or f'none: no *.yaml in {directory}'
        valid = [str(key) for path in files for key in docs[path]] + list(walks)
        close = difflib.get_close_matches(name, valid, n=1)
        guess = f'did you mean {close[0]}? ' if close else ''
        what = 'trajectory or walk' if walks else 'trajectory'
        listed = f'walks: {", ".join(walks)}; ' if walks else ''
        raise TrajectoryError(f'no {what} named {name} in the package\'s trajectory files: '
                              f'{guess}({listed}valid names: {names}); give its file with '
                              '--file')
    both = ' and '.join(path.name for path in holding)
    raise TrajectoryError(f'trajectory {name} is in {both} (searched {searched}); '
                          'choose one with --file')


def companion_gains_file(trajectory_file: Path) -> Path:
    """Where `trajectory_file`'s companion gains would be (whether or not they exist)."""
    return (trajectory_file.parent.parent / 'config'
            / f'{trajectory_file.stem.lower()}{GAINS_SUFFIX}')


@dataclass(frozen=True)
class GainsChoice:
    """The gains file a run uses and why (the demo's progress line says both)."""

    path: Path
    reason: str

    def describe(self) -> str:
        return f'{self.path} ({self.reason})'


def gains_for(trajectory_file: Path, gains_file: Path | None = None) -> GainsChoice:
    """The gains file to play `trajectory_file` with.

    `gains_file` (the user's --gains-file) wins; else the file's companion if it exists;
    else the tutorial's. Nothing is read here: the caller validates the file.
    """
    if gains_file is not None:
        return GainsChoice(gains_file, 'given with --gains-file')
    companion = companion_gains_file(trajectory_file)
    if companion.is_file():
        return GainsChoice(companion, f'the companion of {trajectory_file.name}')
    return GainsChoice(DEFAULT_GAINS_FILE, "the tutorial's")
