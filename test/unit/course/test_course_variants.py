"""The finals' variants of the course: which change each makes, and the rubble rearranged
the same way by the same seed, every block kept as it lies and within the rubble's area."""

from __future__ import annotations

import pytest

from tutorial_atlas_control.course import (
    BLOCKS,
    COURSE_VARIANTS,
    MUD_DAMPING,
    MUD_DAMPING_FINALS,
    CourseError,
    course_variant,
    rearranged_blocks,
)


def test_each_finals_variant_changes_one_thing() -> None:
    base = course_variant('qualification')
    assert (base.mud_damping, base.mud_floor_friction, base.blocks) == (MUD_DAMPING, 0.5, BLOCKS)
    changed = {variant.name: {field for field in ('mud_damping', 'mud_floor_friction', 'blocks')
                              if getattr(variant, field) != getattr(base, field)}
               for variant in COURSE_VARIANTS[1:]}
    assert changed == {'finals_mud_floor': {'mud_floor_friction'},
                       'finals_mud_damping': {'mud_damping'},
                       'finals_rubble': {'blocks'}}
    assert course_variant('finals_mud_floor').mud_floor_friction == 0.3
    assert course_variant('finals_mud_damping').mud_damping == MUD_DAMPING_FINALS


def test_the_rubble_is_rearranged_the_same_way_by_the_same_seed() -> None:
    again = rearranged_blocks(BLOCKS, 7)
    assert again == rearranged_blocks(BLOCKS, 7)
    assert again != rearranged_blocks(BLOCKS, 8)
    # The places are the world's, shuffled: the same set of (x, y), most blocks moved.
    assert sorted((b.x_m, b.y_m) for b in again) == sorted((b.x_m, b.y_m) for b in BLOCKS)
    moved = sum((b.x_m, b.y_m) != (a.x_m, a.y_m) for a, b in zip(BLOCKS, again))
    assert moved >= len(BLOCKS) - 3
    # Each block lies as it lay (flat, on a side, on end), at its own height.
    assert [(b.name, b.z_m, b.roll_rad, b.pitch_rad) for b in again] == \
        [(b.name, b.z_m, b.roll_rad, b.pitch_rad) for b in BLOCKS]
    assert len({b.yaw_rad for b in again}) == len(BLOCKS)


def test_an_unknown_variant_names_the_known_ones() -> None:
    with pytest.raises(CourseError, match="unknown course variant 'finals'; known: "
                                          'qualification, finals_mud_floor'):
        course_variant('finals')
