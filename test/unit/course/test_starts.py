"""A start as the node's ~start, atlas.launch's start and run_offline.py's --start take it: a
VRC world's name or 'x y z yaw', and each wrong form refused with one message saying why."""

from __future__ import annotations

import math

import pytest

from tutorial_atlas_control.course import (
    STARTS,
    CourseError,
    parse_start,
    start_text,
    world_start,
)


def test_a_world_name_gives_drcsims_start() -> None:
    mud = parse_start('vrc_task_2_mud_start')
    assert mud == STARTS['vrc_task_2_mud_start']
    assert (mud.x_m, mud.y_m, mud.yaw_rad) == (-0.29, -23.02, math.pi / 2)
    assert parse_start('  vrc_task_2 ') is STARTS['vrc_task_2']
    assert world_start('vrc_task_2_rubble_start').x_m == 5.49


def test_four_numbers_are_x_y_z_yaw_and_the_yaw_is_wrapped() -> None:
    start = parse_start('3 -2 0.9 1.5707963267948966')
    assert (start.name, start.x_m, start.y_m, start.z_m) == ('', 3.0, -2.0, 0.9)
    assert start.yaw_rad == pytest.approx(math.pi / 2)
    assert parse_start('1, 2, 0, 7').yaw_rad == pytest.approx(7 - 2 * math.pi)
    assert parse_start(start_text(start)) == start  # sim_config's text reads back
    assert start_text(STARTS['vrc_task_2']) == 'vrc_task_2'


def test_an_empty_start_is_none_the_models_own_spawn() -> None:
    assert parse_start('') is None
    assert parse_start('   ') is None


@pytest.mark.parametrize('text, message', [
    ('vrc_task_3', "^start 'vrc_task_3' is not a start name or 'x y z yaw' .*; the names are "
                   'vrc_task_2, vrc_task_2_mud_start, vrc_task_2_uneven_start, '
                   'vrc_task_2_rubble_start$'),
    ('1 2', "^start '1 2' has 2 values; give a start name or 'x y z yaw' "
            r'\(m, m, m, rad; z is only a hint\)$'),
    ('1 2 3 4 5', "^start '1 2 3 4 5' has 5 values"),
    ('1 2 zero 0', "^start '1 2 zero 0': z 'zero' is not a finite number"),
    ('1 nan 0 0', "^start '1 nan 0 0': y 'nan' is not a finite number"),
    ('1 2 0 inf', "^start '1 2 0 inf': yaw 'inf' is not a finite number"),
    ('1e5 0 0 0', "^start '1e5 0 0 0' is more than 10000 m from the origin$"),
])
def test_a_wrong_start_is_refused_saying_why(text: str, message: str) -> None:
    with pytest.raises(CourseError, match=message):
        parse_start(text)


def test_an_unknown_world_lists_the_worlds() -> None:
    with pytest.raises(CourseError, match="^unknown world 'vrc_task_1'; the VRC Task 2 worlds "
                                          'are vrc_task_2, vrc_task_2_mud_start, '):
        world_start('vrc_task_1')
