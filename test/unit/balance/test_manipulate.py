"""Manipulate's pelvis servo: the bent Stand pose keeps the torso parallel to the feet, the
table turns a pelvis height into the bend that gives it, and targets are clamped to reach."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.balance import STAND_POSE_RAD, place_in_stand_pose
from tutorial_atlas_control.balance.manipulate import (
    LATERAL_LIMIT_M,
    PelvisServo,
    SquatTable,
    bent_posture,
    clamp_servo,
)
from tutorial_atlas_control.joints import JOINT_INDEX
from tutorial_atlas_control.sim import AtlasModel, load_model


@pytest.fixture(scope='module')
def atlas() -> AtlasModel:
    return load_model()


@pytest.fixture(scope='module')
def table(atlas: AtlasModel) -> SquatTable:
    return SquatTable(atlas)


@pytest.mark.parametrize('knee_rad', [0.0, 0.518, 1.0])
def test_a_bend_keeps_the_torso_parallel_to_the_feet(knee_rad: float) -> None:
    posture = bent_posture(knee_rad, yaw_rad=0.2)
    for side in 'lr':
        pitches = [posture[JOINT_INDEX[f'{side}_leg_{j}']] for j in ('lhy', 'kny', 'uay')]
        assert pitches[1] == knee_rad
        assert sum(pitches) == pytest.approx(0.0, abs=1e-12)
        assert posture[JOINT_INDEX[f'{side}_leg_uhz']] == -0.2
    others = [i for i, name in enumerate(JOINT_INDEX) if '_leg_' not in name]
    np.testing.assert_array_equal(posture[others], STAND_POSE_RAD[others])


def test_the_table_gives_the_bend_for_a_height(atlas: AtlasModel, table: SquatTable) -> None:
    low, high = table.height_range_m
    assert 0.80 < low < 0.82 and 0.92 < high < 0.93  # measured: 0.8096 and 0.9267 m
    data = mujoco.MjData(atlas.model)
    for height in np.linspace(low, high, 7):
        placed = place_in_stand_pose(atlas, data, bent_posture(table.knee_for(height)))
        assert placed == pytest.approx(height, abs=0.001)
    assert table.stand_height_m == pytest.approx(place_in_stand_pose(atlas, data))
    assert table.com_for(low) < table.com_for(high)


def test_targets_are_clamped_to_what_the_legs_reach(table: SquatTable) -> None:
    low, high = table.height_range_m
    inside = PelvisServo(0.85, 0.1, 0.02)
    assert clamp_servo(inside, table) == inside
    assert clamp_servo(PelvisServo(0.5, -1.0, 1.0), table) == PelvisServo(
        low, -table.yaw_limit_rad, LATERAL_LIMIT_M)
    assert clamp_servo(PelvisServo(2.0, 1.0, -1.0), table) == PelvisServo(
        high, table.yaw_limit_rad, -LATERAL_LIMIT_M)
    assert table.yaw_limit_rad == pytest.approx(0.30)  # the hip yaws' 0.32 rad, less 0.02
