"""Where a run starts Atlas: a VRC Task 2 world's start by name, or a pose typed as numbers.

The simulator's `~start` parameter, atlas.launch's `start` argument and `run_offline.py
--world` all come through here, so a name or a pose is checked once, with one message. A
start fixes the pelvis's (x, y) and yaw; its z is only the hint DRCSim's spawn gave
Gazebo: the simulator puts the soles on the ground under them (sim.start_pose).
"""

from __future__ import annotations

import math

from tutorial_atlas_control.course.errors import CourseError
from tutorial_atlas_control.course.vrc_task_2 import STARTS, WORLD_NAME, Start

__all__ = ['MAX_START_M', 'TERRAIN_FILE', 'WORLD_MODEL_FILE', 'parse_start', 'start_text',
           'world_start']

#: The model file (in the package's sim/) of every VRC Task 2 world: they differ only in
#: their start.
WORLD_MODEL_FILE = f'{WORLD_NAME}.xml'
#: Its terrain's elevation image, beside it (8-bit grey, vrc_task_2.HEIGHTMAP's levels).
TERRAIN_FILE = f'{WORLD_NAME}_terrain.png'
#: A start further than this (m) from the origin on x or y is refused as a typo.
MAX_START_M = 1e4
_FORM = "a start name or 'x y z yaw' (m, m, m, rad; z is only a hint)"


def world_start(name: str) -> Start:
    """The start of the VRC world `name` (a key of STARTS).

    Raises:
        CourseError: `name` is not one of the worlds (the message lists them).
    """
    try:
        return STARTS[name]
    except KeyError:
        raise CourseError(f'unknown world {name!r}; the VRC Task 2 worlds are '
                          f'{", ".join(STARTS)}') from None


def parse_start(text: str) -> Start | None:
    """The start `text` names: a key of STARTS, or four numbers 'x y z yaw' (metres and
    radians, as Gazebo's spawn took them); '' names none (the model's own spawn pose).

    Raises:
        CourseError: anything else, with what was given and the forms taken.
    """
    words = str(text).replace(',', ' ').split()
    if not words:
        return None
    if len(words) == 1 and not _is_number(words[0]):
        if words[0] in STARTS:
            return STARTS[words[0]]
        raise CourseError(f'start {text!r} is not {_FORM}; the names are {", ".join(STARTS)}')
    if len(words) != 4:
        raise CourseError(f'start {text!r} has {len(words)} values; give {_FORM}')
    values = []
    for word, what in zip(words, ('x', 'y', 'z', 'yaw')):
        if not _is_number(word) or not math.isfinite(float(word)):
            raise CourseError(f'start {text!r}: {what} {word!r} is not a finite number; '
                              f'give {_FORM}')
        values.append(float(word))
    x, y, z, yaw = values
    if max(abs(x), abs(y), abs(z)) > MAX_START_M:
        raise CourseError(f'start {text!r} is more than {MAX_START_M:g} m from the origin')
    return Start('', x, y, z, math.remainder(yaw, 2.0 * math.pi))


def start_text(start: Start) -> str:
    """The text parse_start reads back as `start` (its name, else its four numbers)."""
    if start.name:
        return start.name
    return ' '.join(repr(value) for value in (start.x_m, start.y_m, start.z_m, start.yaw_rad))


def _is_number(word: str) -> bool:
    try:
        float(word)
    except ValueError:
        return False
    return True
