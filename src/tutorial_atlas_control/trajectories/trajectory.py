"""Trajectory files of the DRCSim tutorial: loading, validation and interpolation.

A trajectory file is a YAML mapping from trajectory names to lists of waypoints.
Each waypoint is a pair ``[duration_s, "p0 p1 ... p27"]``: the time (s) to move
from where the joints are to the 28 joint positions (rad), given in the order of
:data:`tutorial_atlas_control.joints.JOINT_NAMES`.  The positions may be a string
of whitespace-separated numbers, as in the tutorial's ``Traj_data2.yaml``, or a
YAML list of numbers.

This module is pure (no rospy) so it can be tested without a ROS master; the
ROS glue is :mod:`tutorial_atlas_control.trajectories.traj_yaml_node`.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Union

import numpy as np
import yaml

from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.resources import package_path
from tutorial_atlas_control.units import finite_number
from tutorial_atlas_control.yaml_errors import yaml_problem, yaml_where

__all__ = [
    'PUBLISH_PERIOD_S',
    'TrajectoryError',
    'Waypoint',
    'interpolate',
    'load_trajectory',
    'load_trajectory_file',
    'parse_trajectory',
    'resolve_trajectory_file',
    'sample_count',
]

#: Interval (s) between two published commands: the tutorial's 50 Hz (``dtPublish``).
PUBLISH_PERIOD_S: float = 0.02

#: Slack (in publish periods) under which ``duration / period`` still counts as a whole
#: number, so that float artefacts such as 0.14 / 0.02 == 7.000000000000001 give 7
#: samples rather than 8.
_SAMPLE_COUNT_SLACK: float = 1e-9

PathLike = Union[str, 'os.PathLike[str]']

#: The package's trajectory files. The tutorial runs ``traj_yaml.py Traj_data2.yaml ...``
#: from the folder that holds the file; a bare or relative name that does not exist from
#: the current directory is looked up here (see :func:`resolve_trajectory_file`).
TRAJECTORIES_DIR: Path = package_path('trajectories')


class TrajectoryError(AtlasControlError):
    """A trajectory file cannot be read, or a trajectory in it is malformed."""


@dataclass(frozen=True)
class Waypoint:
    """A trajectory's row: reach `positions` (rad, tutorial joint order) in `duration_s` (s)."""

    duration_s: float
    positions: np.ndarray


def load_trajectory_file(path: PathLike) -> dict[str, object]:
    """Read a trajectory file with ``yaml.safe_load`` and check that its root is a mapping.

    Args:
        path: The YAML file.

    Returns:
        The mapping of trajectory names to (unvalidated) waypoint lists.

    Raises:
        TrajectoryError: The file cannot be read, is empty, is not valid YAML, uses a
            YAML tag that safe loading refuses (``!!python/...``), or its root is not
            a mapping.  The message is a single line that starts with the path.
    """
    try:
        with open(path, encoding='utf-8') as stream:
            text = stream.read()
    except OSError as err:
        reason = err.strerror or str(err)
        raise TrajectoryError(f'{path}: cannot read trajectory file: {reason}') from err
    except UnicodeDecodeError as err:
        raise TrajectoryError(
            f'{path}: cannot read trajectory file: not UTF-8 text ({err.reason})') from err

    try:
        doc = yaml.safe_load(text)
    except yaml.constructor.ConstructorError as err:
        raise TrajectoryError(
            f'{path}: unsupported YAML{yaml_where(err)}: {err.problem}; '
            'trajectory files may only hold plain mappings, lists, numbers and strings'
        ) from err
    except yaml.YAMLError as err:
        raise TrajectoryError(f'{path}: {yaml_problem(err)}') from err

    if doc is None:
        raise TrajectoryError(
            f'{path}: the file is empty; expected a mapping of trajectory names to waypoints')
    if not isinstance(doc, dict):
        raise TrajectoryError(
            f'{path}: expected a mapping of trajectory names to waypoints at the top level, '
            f'got {_kind(doc)}'
        )
    return doc


def parse_trajectory(doc: Mapping[object, object], name: str, path: PathLike) -> list[Waypoint]:
    """Validate and convert trajectory `name` of a loaded trajectory file.

    Args:
        doc: The mapping returned by :func:`load_trajectory_file`.
        name: The trajectory to extract.
        path: The file `doc` came from; only used in error messages.

    Returns:
        The waypoints, in file order (numbered from 0 in messages).

    Raises:
        TrajectoryError: `name` is not in `doc` (the tutorial's "unable to find
            trajectory NAME in FILE"), or the trajectory is not a non-empty list of
            ``[duration_s, positions]`` pairs with a positive finite duration and
            exactly 28 finite joint positions.  The message names file, trajectory,
            waypoint index and problem.
    """
    if name not in doc:
        raise TrajectoryError(unknown_trajectory(doc, name, path))
    rows = doc[name]
    where = f"{path}: trajectory '{name}'"
    if not isinstance(rows, list):
        raise TrajectoryError(
            f'{where}: expected a list of waypoints [duration_s, "positions"], got {_kind(rows)}')
    if not rows:
        raise TrajectoryError(f'{where}: has no waypoints')
    return [_parse_waypoint(row, f'{where}, waypoint {index}') for index, row in enumerate(rows)]


#: The unknown-name error lists at most this many of the file's trajectories.
MAX_NAMES_LISTED = 20


def unknown_trajectory(doc: Mapping[object, object], name: str, path: PathLike) -> str:
    """The tutorial's "unable to find trajectory NAME in FILE", and the names the file has."""
    names = [_shown_name(key) for key in doc]
    if not names:
        return f'unable to find trajectory {name} in {path}; it holds no trajectories'
    listed = ', '.join(names[:MAX_NAMES_LISTED])
    if len(names) > MAX_NAMES_LISTED:
        listed += f', ... ({len(names)} in all)'
    return f'unable to find trajectory {name} in {path}; it holds: {listed}'


def _shown_name(key: object) -> str:
    """A trajectory name as the error lists it: as written when plain, else quoted (one line)."""
    text = str(key)
    if text and text.isprintable() and text == text.strip() and ',' not in text:
        return text
    return repr(text)


def is_explicit_path(path: PathLike) -> bool:
    """Absolute, or anchored at the current directory (``./x.yaml``, ``../x.yaml``)."""
    text = os.fspath(path)
    return os.path.isabs(text) or text.split(os.sep, 1)[0] in ('.', '..')


def resolve_trajectory_file(path: PathLike,
                            search_dir: Path = TRAJECTORIES_DIR) -> tuple[str, bool]:
    """The file a YAML_FILE argument names, and whether it was found in `search_dir`.

    The argument as given when it exists from the current directory, or when it is an
    explicit path (:func:`is_explicit_path`: the user said where it is, so a missing file
    is their mistake, reported by :func:`load_trajectory_file`). Otherwise a bare or
    relative name is looked up in `search_dir`, the package's ``trajectories/``.

    Raises:
        TrajectoryError: a bare or relative name found in neither place (one line).
    """
    text = os.fspath(path)
    if os.path.exists(text) or is_explicit_path(text):
        return text, False
    candidate = search_dir / text
    if candidate.is_file():
        return str(candidate), True
    raise TrajectoryError(f'{text}: cannot read trajectory file: No such file or directory '
                          f'(not in the current directory, nor in {search_dir})')


def locate_trajectory_file(path: PathLike, announce: Callable[[str], None] | None = None,
                           search_dir: Path = TRAJECTORIES_DIR) -> str:
    """YAML_FILE as the tutorial uses it (traj_yaml.py, run_offline.py): a bare name also finds
    the package's trajectories/ copy, and `announce` (the command line's print) says so in
    one line, unless the current directory is the package's own (`roscd
    tutorial_atlas_control`, the tutorial's way): there its trajectories/ is the expected place.

    Raises:
        TrajectoryError: as :func:`resolve_trajectory_file`.
    """
    found, from_package = resolve_trajectory_file(path, search_dir)
    if from_package and announce is not None and not _in_package_dir(search_dir.parent):
        announce(f'{os.fspath(path)} is not in the current directory; using {found}')
    return found


def _in_package_dir(package_dir: Path) -> bool:
    """Whether the current directory is `package_dir` (through any symlink: roscd lands in
    the catkin workspace's src/ link to the clone)."""
    try:
        return Path.cwd().resolve() == package_dir.resolve()
    except OSError:  # the current directory was removed
        return False


def load_trajectory(path: PathLike, name: str) -> list[Waypoint]:
    """Load trajectory `name` from the file at `path`, after validating the whole file.

    Every trajectory is checked, not only `name`: a mistake elsewhere in the file is
    reported now rather than on the run that needs it.

    Raises:
        TrajectoryError: see :func:`load_trajectory_file` and :func:`parse_trajectory`.
    """
    doc = load_trajectory_file(path)
    if name not in doc:
        raise TrajectoryError(unknown_trajectory(doc, name, path))
    for other in doc:
        if other != name:
            parse_trajectory(doc, other, path)
    return parse_trajectory(doc, name, path)


def sample_count(duration_s: float) -> int:
    """Number of commands published for a waypoint lasting `duration_s` (s).

    The tutorial's ``ceil(dt / dtPublish)``, made an ``int`` and at least 1.
    """
    if not (math.isfinite(duration_s) and duration_s > 0.0):
        raise ValueError(f'duration_s must be positive and finite, got {duration_s!r}')
    return max(1, math.ceil(duration_s / PUBLISH_PERIOD_S - _SAMPLE_COUNT_SLACK))


def interpolate(
    initial: np.ndarray, target: np.ndarray, duration_s: float
) -> Iterator[tuple[np.ndarray, float]]:
    """Yield the tutorial's commands from `initial` to `target` over `duration_s`.

    As in the tutorial, ``n = sample_count(duration_s)`` commands
    ``(1 - ratio) * initial + ratio * target`` for ``ratio in linspace(0, 1, n)``,
    each followed by a sleep of ``duration_s / n`` (s): the first command is
    `initial`, the last is `target`, and the whole waypoint lasts `duration_s`.
    With a single sample (``duration_s <= PUBLISH_PERIOD_S``) the tutorial's
    ``linspace(0, 1, 1) == [0]`` would only command `initial`; we command `target`.

    The samples are produced lazily, so a long duration costs no memory.

    Yields:
        ``(positions, sleep_s)``: joint positions (rad) to publish, then the time
        (s, ROS time) to sleep before the next one.
    """
    initial = np.asarray(initial, dtype=float)
    target = np.asarray(target, dtype=float)
    if initial.shape != target.shape:
        raise ValueError(f'initial has shape {initial.shape} but target has shape {target.shape}')
    count = sample_count(duration_s)
    sleep_s = duration_s / count
    if count == 1:
        yield target.copy(), sleep_s
        return
    for index in range(count):
        ratio = 1.0 if index == count - 1 else index / (count - 1)
        yield (1.0 - ratio) * initial + ratio * target, sleep_s


def _parse_waypoint(row: object, where: str) -> Waypoint:
    if not isinstance(row, list) or len(row) != 2:
        raise TrajectoryError(
            f'{where}: expected a pair [duration_s, "{NUM_JOINTS} joint positions"], '
            f'got {_kind(row)}'
        )
    duration_s = finite_number(row[0])
    if duration_s is None:
        raise TrajectoryError(
            f'{where}: duration must be a finite number of seconds, got {_show(row[0])}')
    if duration_s <= 0.0:
        raise TrajectoryError(f'{where}: duration must be positive, got {_show(row[0])} s')
    return Waypoint(duration_s=duration_s, positions=_parse_positions(row[1], where))


def _parse_positions(value: object, where: str) -> np.ndarray:
    if isinstance(value, str):
        items: list[object] = list(value.split())
    elif isinstance(value, list):
        items = value
    else:
        raise TrajectoryError(
            f'{where}: joint positions must be a string of {NUM_JOINTS} numbers or a list of them, '
            f'got {_kind(value)}'
        )
    if len(items) != NUM_JOINTS:
        raise TrajectoryError(f'{where}: expected {NUM_JOINTS} joint positions, got {len(items)}')
    positions = np.empty(NUM_JOINTS)
    for index, item in enumerate(items):
        number = finite_number(item, allow_text=isinstance(value, str))
        if number is None:
            raise TrajectoryError(
                f'{where}: joint position {index} ({JOINT_NAMES[index]}) must be a finite number, '
                f'got {_show(item)}'
            )
        positions[index] = number
    return positions


def _one_line(text: str) -> str:
    return ' '.join(text.split())


def _kind(value: object) -> str:
    if value is None:
        return 'nothing (null)'
    if isinstance(value, list):
        return f'a list of {len(value)} items'
    if isinstance(value, dict):
        return 'a mapping'
    return f'{type(value).__name__} {_show(value)}'


def _show(value: object, limit: int = 40) -> str:
    text = _one_line(repr(value))
    return text if len(text) <= limit else text[: limit - 3] + '...'
