"""Typos in roslaunch's arguments: `recrod:=false` is ignored by roslaunch without a word.

roslaunch refuses an argument a launch file needs and lacks, but not one it was given and
does not declare. The simulator, started by roslaunch, reads its parent's command line and
compares the `name:=value` arguments with the `<arg>`s the launch files on it declare (and
the files they include with pass_all_args, which hands them every argument: the VRC
launches pass atlas.launch's through); each unknown one gets one warning line naming the
closest declared argument.
"""

from __future__ import annotations

import difflib
import re
import xml.etree.ElementTree as ElementTree
from collections.abc import Callable, Sequence
from pathlib import Path

__all__ = ['declared_args', 'given_args', 'included_file', 'launch_files', 'unknown_arg_lines']

#: How alike a declared name must be to be offered as the one meant (difflib's ratio).
SUGGESTION_CUTOFF = 0.6
#: Finds a launch file named on roslaunch's command line without a path: (package, file)
#: -> its path, None when it is not found.
LaunchFinder = Callable[[str, str], Path | None]


def given_args(argv: Sequence[str]) -> dict[str, str]:
    """roslaunch's `name:=value` arguments; remappings and private names (`__name:=`,
    `_param:=`) are not launch arguments."""
    found = {}
    for token in argv:
        name, sep, value = token.partition(':=')
        if sep and name and not name.startswith('_') and '/' not in name:
            found[name] = value
    return found


def launch_files(argv: Sequence[str], find: LaunchFinder) -> list[Path] | None:
    """The launch files roslaunch's command line names (a path, or PACKAGE FILE.launch);
    None when one of them cannot be found (then nothing can be said)."""
    files = []
    for position, token in enumerate(argv):
        if not token.endswith('.launch') or ':=' in token:
            continue
        path = Path(token)
        if path.is_file():
            files.append(path)
            continue
        package = argv[position - 1] if position > 0 else ''
        found = find(package, token)
        if found is None:
            return None
        files.append(found)
    return files or None


def included_file(path: Path, spec: str, find: LaunchFinder) -> Path | None:
    """The file an `<include file=...>` of `path` names, when it is `$(dirname)/X.launch`
    or `$(find PACKAGE)/launch/X.launch`; None for any other form or a file not found."""
    match = re.fullmatch(r'\$\(dirname\)/([\w.-]+\.launch)', spec)
    if match:
        found = path.parent / match.group(1)
        return found if found.is_file() else None
    match = re.fullmatch(r'\$\(find ([\w-]+)\)/launch/([\w.-]+\.launch)', spec)
    return find(match.group(1), match.group(2)) if match else None


def declared_args(path: Path, find: LaunchFinder | None = None,
                  _seen: frozenset[Path] = frozenset()) -> set[str] | None:
    """The `<arg name=...>` of a launch file's top level, and with `find`, those of the files
    it includes with pass_all_args="true"; None if one cannot be read or found."""
    try:
        root = ElementTree.parse(path).getroot()
    except (OSError, ElementTree.ParseError):
        return None
    names = {element.get('name', '') for element in root.findall('arg')}
    if find is None:
        return names
    seen = _seen | {path.resolve()}
    for include in root.findall('include'):
        if include.get('pass_all_args', 'false').lower() != 'true':
            continue
        child = included_file(path, include.get('file', ''), find)
        if child is None:
            return None
        inner = names if child.resolve() in seen else declared_args(child, find, seen)
        if inner is None:
            return None
        names |= inner
    return names


def unknown_arg_lines(argv: Sequence[str], find: LaunchFinder) -> list[str]:
    """One warning line per argument roslaunch was given that no launch file declares."""
    files = launch_files(argv, find)
    if files is None:
        return []
    declared: set[str] = set()
    for path in files:
        names = declared_args(path, find)
        if names is None:
            return []
        declared |= names
    lines = []
    for name, value in given_args(argv).items():
        if name in declared:
            continue
        close = difflib.get_close_matches(name, sorted(declared), n=1, cutoff=SUGGESTION_CUTOFF)
        hint = f'; did you mean {close[0]}:={value}?' if close else ''
        lines.append(f'roslaunch ignored the argument {name}:={value}: '
                     f'{", ".join(path.name for path in files)} has no argument {name}{hint} '
                     f'(its arguments: {", ".join(sorted(declared))})')
    return lines
