"""How much the bag directory holds, and which old bags go: atlas.launch's retention and
`make clean-bags`.

Recording is on by default and a live run takes about 67 MB per minute of sim time, so bags
pile up (15 minutes of trying left 409 MB in 22 bags). The launch says what the directory
holds when it starts; a retention setting (keep the newest N bags, a size cap, or both; off
by default) deletes the oldest closed bags, atlas_*.bag only: never a recording still open
(.bag.active), nor any other file.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from tutorial_atlas_control.errors import AtlasControlError

__all__ = ['KEEP_BAGS_ENV', 'MAX_BAGS_MB_ENV', 'BagFile', 'RetentionError', 'Retention',
           'bag_files', 'bags_count', 'doomed', 'retention_from_env', 'size_mb', 'usage_line']

#: The environment variables atlas.launch's keep_bags and max_bags_mb defaults read.
KEEP_BAGS_ENV = 'TAC_KEEP_BAGS'
MAX_BAGS_MB_ENV = 'TAC_MAX_BAGS_MB'
#: Bytes per MB, as `ls -h` and the README's figures count them (10^6).
BYTES_PER_MB = 1_000_000
#: The bags atlas.launch writes (closed ones).
BAG_GLOB = 'atlas_*.bag'


class RetentionError(AtlasControlError):
    """A retention setting that is not a whole number >= 0."""


@dataclass(frozen=True)
class BagFile:
    path: Path
    size_bytes: int
    mtime_s: float


@dataclass(frozen=True)
class Retention:
    """keep_bags: at most this many bags (0: no limit); max_bytes: at most this many bytes
    of bags (0: no limit)."""

    keep_bags: int = 0
    max_bytes: int = 0

    @property
    def off(self) -> bool:
        return self.keep_bags == 0 and self.max_bytes == 0


def size_mb(size_bytes: int) -> str:
    return f'{size_bytes / BYTES_PER_MB:.0f} MB'


def bags_count(count: int) -> str:
    return f'{count} bag' if count == 1 else f'{count} bags'


def bag_files(directory: Path) -> list[BagFile]:
    """The closed bags atlas.launch wrote in `directory`, oldest first; [] if it is missing."""
    found = []
    for path in directory.glob(BAG_GLOB):
        try:
            stat = path.stat()
        except OSError:  # deleted meanwhile
            continue
        if path.is_file():
            found.append(BagFile(path, stat.st_size, stat.st_mtime))
    return sorted(found, key=lambda bag: (bag.mtime_s, bag.path.name))


def doomed(bags: list[BagFile], retention: Retention, coming: int = 0) -> list[BagFile]:
    """The oldest of `bags` (oldest first) to delete so that the rest keep `retention`,
    counting `coming` bags about to be written (a starting launch's: 1) in keep_bags."""
    if retention.off:
        return []
    total = sum(bag.size_bytes for bag in bags)
    gone = []
    for index, bag in enumerate(bags):
        left = len(bags) - index + coming
        over_count = retention.keep_bags and left > retention.keep_bags
        over_size = retention.max_bytes and total > retention.max_bytes
        if not (over_count or over_size):
            break
        gone.append(bag)
        total -= bag.size_bytes
    return gone


def usage_line(directory: Path, bags: list[BagFile]) -> str:
    total = sum(bag.size_bytes for bag in bags)
    return f'bag directory {directory}: {bags_count(len(bags))}, {size_mb(total)}'


def _whole_number(text: str, name: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise RetentionError(f'{name} must be a whole number >= 0 (0: no limit), got {text!r}')
    return value


def retention_from_env(env: dict[str, str] | None = None) -> Retention:
    """$TAC_KEEP_BAGS and $TAC_MAX_BAGS_MB (unset or empty: no limit).

    Raises:
        RetentionError: a value that is not a whole number >= 0.
    """
    env = dict(os.environ if env is None else env)
    keep = _whole_number(env.get(KEEP_BAGS_ENV) or '0', KEEP_BAGS_ENV)
    max_mb = _whole_number(env.get(MAX_BAGS_MB_ENV) or '0', MAX_BAGS_MB_ENV)
    return Retention(keep, max_mb * BYTES_PER_MB)
