"""The course's figures: the heightmap's scaling and the boxes as DRCSim's files give them."""

from __future__ import annotations

import math

import pytest

from tutorial_atlas_control.course import GATES, HEIGHTMAP, MUD_BOX, STARTS


def test_heightmap_scales_as_gazebo_did() -> None:
    assert HEIGHTMAP.height_m(0) == pytest.approx(-0.6)
    assert HEIGHTMAP.height_m(250) == pytest.approx(2.9)
    # The course's flat ground (grey 45) at about z 0.03, one grey level 1.4 cm.
    assert HEIGHTMAP.height_m(45) == pytest.approx(0.03)
    assert HEIGHTMAP.height_m(1) - HEIGHTMAP.height_m(0) == pytest.approx(0.014)
    assert HEIGHTMAP.cell_m == pytest.approx(100 / 512)


def test_mud_box_top_is_at_minus_0_13_and_holds_the_pit_floor() -> None:
    top = MUD_BOX.centre_m[2] + MUD_BOX.size_m[2] / 2
    assert top == pytest.approx(-0.13)
    assert MUD_BOX.contains(0.5, -16.6, -0.55)
    assert not MUD_BOX.contains(0.5, -16.6, 0.0)
    assert not MUD_BOX.contains(5.0, -16.6, -0.3)


def test_gates_in_scoring_order_and_starts_named_as_drcsim_worlds() -> None:
    assert [gate.name for gate in GATES] == [f'gate_{n}' for n in range(5)]
    assert [gate.y_m for gate in GATES] == sorted(gate.y_m for gate in GATES)
    assert set(STARTS) == {'vrc_task_2', 'vrc_task_2_mud_start', 'vrc_task_2_uneven_start',
                           'vrc_task_2_rubble_start'}
    assert STARTS['vrc_task_2_mud_start'].yaw_rad == pytest.approx(math.pi / 2)
