"""Bag housekeeping: what the bag directory holds as a launch starts, and deleting old bags.

`python3 -m tutorial_atlas_control.cli.bag_housekeeping launch BAG_DIR` (record_run.sh, as
the recorder starts): one line with the directory's bags and size, then the retention of
$TAC_KEEP_BAGS / $TAC_MAX_BAGS_MB (atlas.launch's keep_bags:= and max_bags_mb:=), counting
the bag about to be written, with one line when it deletes.
`... clean [BAG_DIR] [--keep N]` (`make clean-bags`): deletes the bags, all but the newest N.
Only closed atlas_*.bag files are deleted, never a recording in progress (.bag.active).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path

from tutorial_atlas_control.bags import (
    BagFile,
    Retention,
    RetentionError,
    bag_files,
    bags_count,
    default_bag_dir,
    doomed,
    retention_from_env,
    size_mb,
    usage_line,
)
from tutorial_atlas_control.cli.convention import EXIT_REFUSED, print_error

PROG = 'bag_housekeeping'
#: The prefix of the launch's lines: they come from the recorder's start-up script.
LAUNCH_PROG = 'record_run.sh'
#: Exit status of a bad setting (a command line's, as argparse's).
EXIT_USAGE = 2


def delete(bags: list[BagFile]) -> tuple[int, int]:
    """Delete `bags`; (count, bytes) actually deleted (one gone meanwhile is skipped)."""
    count = size = 0
    for bag in bags:
        try:
            bag.path.unlink()
        except FileNotFoundError:
            continue
        count += 1
        size += bag.size_bytes
    return count, size


def _setting(retention: Retention) -> str:
    parts = []
    if retention.keep_bags:
        parts.append(f'keep_bags={retention.keep_bags}')
    if retention.max_bytes:
        parts.append(f'max_bags_mb={retention.max_bytes // 1_000_000}')
    return ', '.join(parts)


def launch(directory: Path) -> int:
    """The launch's start: usage line, then the retention of the environment's setting."""
    try:
        retention = retention_from_env()
    except RetentionError as err:
        print(f'{LAUNCH_PROG}: error: {err}; not recording', file=sys.stderr)
        return EXIT_USAGE
    bags = bag_files(directory)
    hint = ('' if not retention.off else
            ' (keep_bags:= or max_bags_mb:= limit it; make clean-bags empties it)')
    print(f'{LAUNCH_PROG}: {usage_line(directory, bags)}{hint}', flush=True)
    try:
        count, size = delete(doomed(bags, retention, coming=1))
    except OSError as err:
        print(f'{LAUNCH_PROG}: cannot delete old bags in {directory} '
              f'({err.strerror or err}); recording anyway', file=sys.stderr)
        return 0
    if count:
        print(f'{LAUNCH_PROG}: deleted {count} old {"bag" if count == 1 else "bags"} '
              f'({size_mb(size)}) in {directory} to keep {_setting(retention)} (counting this '
              "run's)", flush=True)
    return 0


def clean(directory: Path, keep: int) -> int:
    """`make clean-bags`: all bags but the newest `keep` deleted; one line."""
    bags = bag_files(directory)
    gone = bags[:len(bags) - keep] if keep else bags
    count, size = delete(gone)
    left = bag_files(directory)
    print(f'deleted {bags_count(count)} ({size_mb(size)}) in {directory}; '
          f'{usage_line(directory, left).split(": ", 1)[1]} left')
    return 0


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=PROG, description=__doc__.split('\n', 1)[0])
    commands = parser.add_subparsers(dest='command', required=True)
    starting = commands.add_parser('launch', help="the launch's start (record_run.sh)")
    starting.add_argument('bag_dir', type=Path, metavar='BAG_DIR')
    cleaning = commands.add_parser('clean', help='delete the bags (make clean-bags)')
    cleaning.add_argument('bag_dir', type=Path, metavar='BAG_DIR', nargs='?',
                          help='default: $TAC_BAG_DIR, else ~/.ros/tutorial_atlas_control/bags')
    cleaning.add_argument('--keep', type=int, default=0, metavar='N',
                          help='keep the newest N bags (default: 0, delete all)')
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    if args.command == 'launch':
        return launch(args.bag_dir)
    if args.keep < 0:
        parser.error(f'--keep must be >= 0, got {args.keep}')
    directory = args.bag_dir if args.bag_dir is not None else default_bag_dir()
    try:
        return clean(directory, args.keep)
    except OSError as err:
        print_error(PROG, f'cannot delete in {directory}: {err.strerror or err}')
        return EXIT_REFUSED


if __name__ == '__main__':
    sys.exit(main())
