"""The command-line convention every script of the package follows.

One line on stderr per error, `<script>: error: <message>` as argparse prints it, and no
traceback. Exit status 0 on success, 1 when the input or the environment is refused (a
bag, a file, no ROS master), 2 when the command line is (argparse, including option values
out of range), 3 when replay_bag.py's replay deviates, 130 on Ctrl-C. traj_yaml.py keeps
the DRCSim tutorial's command line instead: its usage and exit status 1 (130 on Ctrl-C too).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from typing import TypeVar

from tutorial_atlas_control.bags import newest_bag
from tutorial_atlas_control.errors import AtlasControlError

_T = TypeVar('_T')

#: Exit status of a refused input or environment (a bag, a file, no ROS master).
EXIT_REFUSED = 1
#: Exit status on Ctrl-C: 128 + SIGINT, as a shell reports a process the signal ended.
EXIT_INTERRUPTED = 130


def argument_type(convert: Callable[[str], _T]) -> Callable[[str], _T]:
    """An argparse `type=` from a converter that raises AtlasControlError on a bad value.

    argparse then reports the converter's message and exits 2, as for any bad argument.
    """
    def checked(text: str) -> _T:
        try:
            return convert(text)
        except AtlasControlError as err:
            raise argparse.ArgumentTypeError(str(err)) from None
    checked.__name__ = convert.__name__
    return checked


def whole_number(minimum: int) -> Callable[[str], int]:
    """An argparse `type=` for a whole number >= `minimum`: out of range is a wrong command
    line (exit 2), as a malformed value is."""
    def checked(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f'{text!r} is not a whole number') from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f'{text!r} must be at least {minimum}')
        return value
    checked.__name__ = 'whole_number'
    return checked


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'{text!r} is not a number') from None


def positive_number(text: str) -> float:
    """An argparse `type=` for a finite number > 0 (a stride, a duration, a time scale)."""
    value = _number(text)
    if not 0.0 < value < float('inf'):
        raise argparse.ArgumentTypeError(f'{text!r} must be a finite number > 0')
    return value


def non_negative_number(text: str) -> float:
    """An argparse `type=` for a finite number >= 0 (a gain that may be off)."""
    value = _number(text)
    if not 0.0 <= value < float('inf'):
        raise argparse.ArgumentTypeError(f'{text!r} must be a number >= 0')
    return value


def seed_or_none(text: str) -> int | None:
    """An argparse `type=` for a run's seed: an integer, or `none` (the unperturbed run)."""
    if text == 'none':
        return None
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'seed {text!r} is not an integer or none') from None


#: A wrong command line (argparse's status).
EXIT_USAGE = 2
HELP_OPTIONS = ('-h', '--help')


def node_arguments(prog: str, doc: str, plain: Sequence[str]) -> int | None:
    """A node script's command line without its ROS arguments (`plain`): none, else
    -h/--help (the docstring `doc`, exit 0) or one line for anything else (exit 2); None
    when the node may start."""
    if not plain:
        return None
    if plain[0] in HELP_OPTIONS:
        print(doc.strip())
        return 0
    print_error(prog, f'unexpected argument {plain[0]!r} (see --help)')
    return EXIT_USAGE


def print_error(prog: str, message: object) -> None:
    """The one stderr line of a refused run."""
    print(f'{prog}: error: {message}', file=sys.stderr)


def add_bag_arguments(parser: argparse.ArgumentParser, verb: str) -> None:
    """BAG, optional, and --latest: the newest bag in atlas.launch's bag directory."""
    parser.add_argument('bag', metavar='BAG', nargs='?',
                        help=f'the ROS 1 .bag file to {verb} (default: the newest bag in the '
                             'bag directory, as --latest)')
    parser.add_argument('--latest', action='store_true',
                        help=f'{verb} the newest .bag in $TAC_BAG_DIR, else '
                             '~/.ros/tutorial_atlas_control/bags')


def check_bag_arguments(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Exit 2 (argparse) when both BAG and --latest are given."""
    if args.bag and args.latest:
        parser.error('give BAG or --latest, not both')


def chosen_bag(args: argparse.Namespace, doing: str) -> str:
    """BAG, or the newest bag (said on stderr: `<doing> PATH (the newest bag)`, naming the
    newer empty or unreadable bags it skipped).

    Raises:
        AtlasControlError: no BAG, and no bag in the bag directory.
    """
    if args.bag:
        return str(args.bag)
    newest = newest_bag()
    print(f'{doing} {newest.path} (the newest bag{newest.skipped_note()})', file=sys.stderr)
    return str(newest.path)


def add_dask_arguments(parser: argparse.ArgumentParser, progress: bool = True) -> None:
    """--workers and --scheduler (and --no-progress) of the scripts whose runs are Dask
    tasks (search/sweep.py's engine)."""
    parser.add_argument('--workers', type=whole_number(1), default=None, metavar='N',
                        help='local cluster size (default: one per core; 1: the runs in this '
                             'process, no cluster)')
    parser.add_argument('--scheduler', metavar='ADDRESS',
                        help='use this Dask scheduler (e.g. tcp://host:8786), not a local cluster')
    if progress:
        parser.add_argument('--no-progress', action='store_true', help='no progress bar')
