"""Where atlas.launch records its bags, and the newest one: `BAG` when none is given.

atlas.launch writes atlas_<YYYY-MM-DD-HH-MM-SS>.bag into `bag_dir`, whose default is
$TAC_BAG_DIR, else ~/.ros/tutorial_atlas_control/bags; a shell glob such as atlas_*.bag
names every bag there, so the scripts pick the newest themselves.
"""

from __future__ import annotations

import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

from tutorial_atlas_control.errors import BagAnalysisError

__all__ = ['BAG_DIR_ENV', 'NewestBag', 'bag_problem', 'default_bag_dir', 'latest_bag',
           'newest_bag', 'unwritable_reason']

#: The environment variable atlas.launch's bag_dir default reads.
BAG_DIR_ENV = 'TAC_BAG_DIR'


def default_bag_dir() -> Path:
    """atlas.launch's default bag_dir: $TAC_BAG_DIR, else ~/.ros/tutorial_atlas_control/bags."""
    configured = os.environ.get(BAG_DIR_ENV)
    if configured:
        return Path(configured).expanduser()
    return Path.home() / '.ros' / 'tutorial_atlas_control' / 'bags'


def bag_problem(path: Path) -> str | None:
    """Why `path` cannot be "the newest bag": 'empty' (no message, as a launch that stopped
    before its simulator was ready leaves with `rosbag record`), 'unreadable (...)'; None
    if it opens and holds messages. Reads the index only."""
    # Here, not at the top: the scripts' convention module imports this one before it can
    # say that the shell lacks the environment (rosbags).
    from tutorial_atlas_control.bags.records import open_bag  # noqa: PLC0415

    try:
        bag = open_bag(path, fast=False)
    except BagAnalysisError as err:
        return f'unreadable: {str(err).rstrip(".")}'
    try:
        count = sum(connection.msgcount for connection in bag.connections)
    finally:
        bag.close()
    return 'empty' if count == 0 else None


@dataclass(frozen=True)
class NewestBag:
    """The newest usable bag, and the newer ones passed over (file name, why)."""

    path: Path
    skipped: tuple[tuple[str, str], ...] = ()

    def skipped_note(self) -> str:
        """'; skipped NAME (why), ...' or ''."""
        if not self.skipped:
            return ''
        return '; skipped ' + ', '.join(f'{name} ({why})' for name, why in self.skipped)


def _bags_and_active(directory: Path) -> tuple[list[Path], list[str]]:
    try:
        bags = [path for path in directory.iterdir()
                if path.name.endswith('.bag') and path.is_file()]
        active = sorted(path.name for path in directory.iterdir()
                        if path.name.endswith('.bag.active'))
    except OSError as err:
        raise BagAnalysisError(f'no bag given and the bag directory {directory} cannot be read '
                               f'({err.strerror or err}); give BAG, or set {BAG_DIR_ENV}.'
                               ) from None
    return bags, active


def newest_bag(directory: Path | None = None) -> NewestBag:
    """The most recently modified .bag in `directory` (default: :func:`default_bag_dir`)
    that holds messages and opens; newer empty or unreadable ones are skipped and named.

    Raises:
        BagAnalysisError: the directory holds no usable .bag (the message says what it holds).
    """
    directory = default_bag_dir() if directory is None else directory
    bags, active = _bags_and_active(directory)
    skipped: list[tuple[str, str]] = []
    for path in sorted(bags, key=lambda path: (path.stat().st_mtime, path.name), reverse=True):
        problem = bag_problem(path)
        if problem is None:
            return NewestBag(path, tuple(skipped))
        skipped.append((path.name, problem))
    hint = (f' ({active[-1]} is an interrupted recording: run `rosbag reindex '
            f'{directory / active[-1]}`)' if active else '')
    found = (f'no usable .bag in {directory} (' + ', '.join(
        f'{name}: {why}' for name, why in skipped) + ')') if skipped else f'no .bag in {directory}'
    raise BagAnalysisError(f'no bag given and {found}{hint}; give BAG, or set {BAG_DIR_ENV}.')


def latest_bag(directory: Path | None = None) -> Path:
    """:func:`newest_bag`'s path."""
    return newest_bag(directory).path


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
