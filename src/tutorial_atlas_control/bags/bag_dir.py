"""Where atlas.launch records its bags, and the newest one: `BAG` when none is given.

atlas.launch writes atlas_<YYYY-MM-DD-HH-MM-SS>.bag into `bag_dir`, whose default is
$TAC_BAG_DIR, else ~/.ros/tutorial_atlas_control/bags; a shell glob such as atlas_*.bag
names every bag there, so the scripts pick the newest themselves.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from tutorial_atlas_control.errors import BagAnalysisError

__all__ = ['BAG_DIR_ENV', 'default_bag_dir', 'latest_bag', 'unwritable_reason']

#: The environment variable atlas.launch's bag_dir default reads.
BAG_DIR_ENV = 'TAC_BAG_DIR'


def default_bag_dir() -> Path:
    """atlas.launch's default bag_dir: $TAC_BAG_DIR, else ~/.ros/tutorial_atlas_control/bags."""
    configured = os.environ.get(BAG_DIR_ENV)
    if configured:
        return Path(configured).expanduser()
    return Path.home() / '.ros' / 'tutorial_atlas_control' / 'bags'


def latest_bag(directory: Path | None = None) -> Path:
    """The most recently modified .bag in `directory` (default: :func:`default_bag_dir`).

    Raises:
        BagAnalysisError: the directory holds no .bag (the message says what it holds).
    """
    directory = default_bag_dir() if directory is None else directory
    try:
        bags = [path for path in directory.iterdir()
                if path.name.endswith('.bag') and path.is_file()]
        active = sorted(path.name for path in directory.iterdir()
                        if path.name.endswith('.bag.active'))
    except OSError as err:
        raise BagAnalysisError(f'no bag given and the bag directory {directory} cannot be read '
                               f'({err.strerror or err}); give BAG, or set {BAG_DIR_ENV}.'
                               ) from None
    if not bags:
        hint = (f' ({active[-1]} is an interrupted recording: run `rosbag reindex '
                f'{directory / active[-1]}`)' if active else '')
        raise BagAnalysisError(f'no bag given and no .bag in {directory}{hint}; give BAG, or set '
                               f'{BAG_DIR_ENV}.')
    return max(bags, key=lambda path: (path.stat().st_mtime, path.name))


def unwritable_reason(directory: Path) -> str | None:
    """Why no bag can be written in `directory` (created if missing), or None if one can.

    Tried by creating and removing a file: permission bits say nothing to root, nor about a
    read-only mount.
    """
    try:
        directory.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=directory, prefix='.atlas_write_check_'):
            pass
    except OSError as err:
        return err.strerror or str(err)
    return None
