"""The VRC finals' variants of the walking course, as this package builds them.

The VRC finals (`vrc_arenas`, tasks 6-10) ran the Task 2 course with one change each:
the pen and gate_0 moved; the mud pit's floor at mu 0.3 (0.5 in the qualification's
world); the mud's damping 70 N s/m (40); the rubble rearranged; another heightmap. Their
world files are not in DRCSim 2.x, so the changes that matter to a walker are made here from
the qualification's world: the mud floor's friction, the mud's damping, and the rubble
rearranged by a seed (the 30 blocks' places shuffled among themselves, each block turned
to a new heading drawn uniformly, each lying as it lay: flat, on a side or on end). The
moved pen and the other heightmap are not made (their files are unknown).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from tutorial_atlas_control.course.errors import CourseError
from tutorial_atlas_control.course.vrc_task_2 import (
    BLOCKS,
    MUD_DAMPING,
    MUD_DAMPING_FINALS,
    MUD_FLOOR_FRICTION,
    MUD_FLOOR_FRICTION_FINALS,
    Block,
)

__all__ = ['COURSE_VARIANTS', 'RUBBLE_SEED', 'CourseVariant', 'course_variant',
           'rearranged_blocks']

#: The finals' rubble as this package rearranges it (rearranged_blocks' seed).
RUBBLE_SEED = 2013


@dataclass(frozen=True)
class CourseVariant:
    """One world of the course: the mud's damping (N s/m), the mud floor's friction, and the
    rubble's seed (None: the blocks where the qualification's world puts them)."""

    name: str
    description: str
    mud_damping: float = MUD_DAMPING
    mud_floor_friction: float = MUD_FLOOR_FRICTION
    rubble_seed: int | None = None

    @property
    def blocks(self) -> tuple[Block, ...]:
        """The rubble's 30 blocks in this variant."""
        return BLOCKS if self.rubble_seed is None else rearranged_blocks(BLOCKS,
                                                                         self.rubble_seed)


#: The qualification's course and the finals' three changes a walker meets, one each.
COURSE_VARIANTS: tuple[CourseVariant, ...] = (
    CourseVariant('qualification', 'the VRC Task 2 world as DRCSim 2.x ships it'),
    CourseVariant('finals_mud_floor', f'the mud pit\'s floor at mu {MUD_FLOOR_FRICTION_FINALS}',
                  mud_floor_friction=MUD_FLOOR_FRICTION_FINALS),
    CourseVariant('finals_mud_damping', f'the mud\'s damping {MUD_DAMPING_FINALS:g} N s/m',
                  mud_damping=MUD_DAMPING_FINALS),
    CourseVariant('finals_rubble', f'the rubble rearranged (seed {RUBBLE_SEED}: places '
                  'shuffled, headings drawn anew)', rubble_seed=RUBBLE_SEED),
)


def course_variant(name: str) -> CourseVariant:
    """The variant called `name`.

    Raises:
        CourseError: no variant has that name.
    """
    for variant in COURSE_VARIANTS:
        if variant.name == name:
            return variant
    known = ', '.join(variant.name for variant in COURSE_VARIANTS)
    raise CourseError(f'unknown course variant {name!r}; known: {known}')


def rearranged_blocks(blocks: tuple[Block, ...], seed: int) -> tuple[Block, ...]:
    """`blocks` with their places (x, y) shuffled among them and each a new heading drawn
    uniformly from default_rng(seed); each keeps its name, its height in the world file
    and the way it lies (roll, pitch). The same seed gives the same rubble."""
    rng = np.random.default_rng(seed)
    order = rng.permutation(len(blocks))
    yaws = rng.uniform(-math.pi, math.pi, len(blocks))
    return tuple(replace(block, x_m=blocks[k].x_m, y_m=blocks[k].y_m,
                         yaw_rad=round(float(yaw), 6))
                 for block, k, yaw in zip(blocks, order, yaws))
