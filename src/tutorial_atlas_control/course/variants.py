"""The VRC finals' variants of the walking course, as this package builds them.

The VRC finals (`vrc_arenas`, tasks 6-10) ran the Task 2 course with one change each:
the pen and gate_0 moved; the mud pit's floor at mu 0.3 (0.5 in the qualification's
world); the mud's damping 70 N s/m (40); the rubble rearranged; another heightmap. Their
world files are not in DRCSim 2.x, so the changes that matter to a walker are made here from
the qualification's world: the mud floor's friction, the mud's damping, and the rubble
rearranged by a seed (the 30 blocks' places shuffled among themselves, each block turned
to a new heading drawn uniformly, drawn again while it would overlap a block placed before
it, each lying as it lay: flat, on a side or on end). The moved pen and the other heightmap
are not made (their files are unknown).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from tutorial_atlas_control.course.errors import CourseError
from tutorial_atlas_control.course.mud import check_mud_damping
from tutorial_atlas_control.course.rubble_way import footprints_within
from tutorial_atlas_control.course.vrc_task_2 import (
    BLOCKS,
    MUD_DAMPING,
    MUD_DAMPING_FINALS,
    MUD_FLOOR_FRICTION,
    MUD_FLOOR_FRICTION_FINALS,
    Block,
)

__all__ = ['BLOCK_GAP_M', 'COURSE_VARIANTS', 'RUBBLE_SEED', 'CourseVariant', 'course_variant',
           'rearranged_blocks']

#: The finals' rubble as this package rearranges it (rearranged_blocks' seed).
RUBBLE_SEED = 2013
#: The least gap (m) between two rearranged blocks' footprints. Blocks drawn overlapping are
#: pushed apart by the physics as the world starts: two of the rubble of seed 2013 (before
#: headings were drawn again) lay 1 m from their described places, one on the planned way,
#: and a walk's step landed on its top (0.23 m) where the plan had the ground.
BLOCK_GAP_M = 0.02
#: Headings drawn for one block before its place is given up as too tight.
MAX_HEADING_DRAWS = 200


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

    def with_mud_damping(self, damping: object) -> CourseVariant:
        """This variant with the mud's damping `damping` (N s/m) instead, named so
        (`<name>+mud_damping=<c>`): how far a walk is from falling in the mud is found by
        walking it at dampings between the qualification's and the finals'.

        Raises:
            CourseError: not a finite number, negative or absurd (course.check_mud_damping).
        """
        value = check_mud_damping(damping)
        return replace(self, name=f'{self.name}+mud_damping={value:g}',
                       description=f'{self.description}; the mud\'s damping {value:g} N s/m',
                       mud_damping=value)


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
    uniformly from default_rng(seed), drawn again (from a stream of its own, so that the
    other blocks keep theirs) while its footprint comes within BLOCK_GAP_M of a block placed
    before it; each keeps its name, its height in the world file and the way it lies (roll,
    pitch). The same seed gives the same rubble.

    Raises:
        CourseError: a place where no heading drawn leaves the gap.
    """
    rng = np.random.default_rng(seed)
    order = rng.permutation(len(blocks))
    yaws = rng.uniform(-math.pi, math.pi, len(blocks))
    redraws = np.random.default_rng([seed, 1])
    placed: list[Block] = []
    for block, k, yaw in zip(blocks, order, yaws):
        moved = replace(block, x_m=blocks[k].x_m, y_m=blocks[k].y_m, yaw_rad=round(float(yaw), 6))
        for _ in range(MAX_HEADING_DRAWS):
            if not any(footprints_within(moved, other, BLOCK_GAP_M) for other in placed):
                break
            moved = replace(moved, yaw_rad=round(float(redraws.uniform(-math.pi, math.pi)), 6))
        else:
            raise CourseError(f'rubble seed {seed}: no heading of {block.name} at '
                              f'({moved.x_m}, {moved.y_m}) keeps {BLOCK_GAP_M} m from the '
                              'blocks placed before it')
        placed.append(moved)
    return tuple(placed)
