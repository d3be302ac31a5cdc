"""Manipulate's pelvis servo: the bent Stand pose keeps the torso parallel to the feet, the
tipped squat below it keeps the soles flat and the centre of mass where the level range left
it, the table turns a pelvis height into the posture that gives it, and targets are clamped
to reach."""

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
    pelvis_pitch_rad,
    place_pitched,
)
from tutorial_atlas_control.balance.sole import SOLE_GEOMS, sole_corners
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
    # measured: 0.7233 (the hip pitch's limit), 0.8096 (the ankle's) and 0.9267 m
    assert 0.72 < low < 0.73 and 0.80 < table.level_floor_m < 0.82 and 0.92 < high < 0.93
    data = mujoco.MjData(atlas.model)
    for height in np.linspace(table.level_floor_m, high, 7):
        knee = table.knee_for(height)
        np.testing.assert_allclose(table.posture_for(height), bent_posture(knee), atol=1e-9)
        assert table.pitch_for(height) == pytest.approx(0.0, abs=1e-12)
        placed = place_in_stand_pose(atlas, data, bent_posture(knee))
        assert placed == pytest.approx(height, abs=0.001)
    assert table.stand_height_m == pytest.approx(place_in_stand_pose(atlas, data))
    assert table.com_for(low) < table.com_for(table.level_floor_m) < table.com_for(high)


def _com_ahead_of_soles_m(atlas: AtlasModel, data: mujoco.MjData) -> float:
    soles = [data.geom(name).xpos[0] for name in SOLE_GEOMS]
    return float(data.subtree_com[0][0] - np.mean(soles))


def test_below_the_ankles_reach_the_pelvis_tips_and_the_soles_stay_flat(
        atlas: AtlasModel, table: SquatTable) -> None:
    """The tipped range: the knee bends on, the ankle stays, the pelvis leans forward by the
    pitches' sum, the soles lie flat, and the mass stays where the level range left it."""
    data = mujoco.MjData(atlas.model)
    floor = table.level_floor_m
    place_pitched(atlas, data, table.posture_for(floor))
    level_ahead = _com_ahead_of_soles_m(atlas, data)
    ankle = JOINT_INDEX['l_leg_uay']
    previous_pitch = 0.0
    for height in np.linspace(floor - 0.005, table.height_range_m[0], 6):
        posture = table.posture_for(height)
        pitch = table.pitch_for(height)
        assert pitch == pytest.approx(pelvis_pitch_rad(posture), abs=1e-9)
        assert pitch > previous_pitch  # lower leans further
        previous_pitch = pitch
        assert posture[ankle] == pytest.approx(table.posture_for(floor)[ankle], abs=0.03)
        assert place_pitched(atlas, data, posture) == pytest.approx(height, abs=0.001)
        for name in SOLE_GEOMS:
            assert np.ptp(sole_corners(atlas.model, data, name)[:, 2]) < 0.003  # flat: < 3 mm
        assert _com_ahead_of_soles_m(atlas, data) == pytest.approx(level_ahead, abs=0.002)
        assert table.com_for(height) == pytest.approx(float(data.subtree_com[0][2]), abs=0.001)
    assert table.pitch_for(0.75) == pytest.approx(0.53, abs=0.02)  # measured 0.534 rad
    lhy_low = atlas.model.jnt_range[atlas.model.joint('l_leg_lhy').id][0]
    assert table.posture_for(table.height_range_m[0])[JOINT_INDEX['l_leg_lhy']] > lhy_low


def test_the_table_has_no_jump_in_posture(table: SquatTable) -> None:
    """Adjacent rows differ little: a transition along the table never jumps."""
    steps = np.abs(np.diff(table.postures_rad, axis=0)).max(axis=1)
    assert steps.max() < 0.08  # measured: 0.052 rad (the tipped hip, per 0.02 rad of knee)


def test_targets_are_clamped_to_what_the_legs_reach(table: SquatTable) -> None:
    low, high = table.height_range_m
    inside = PelvisServo(0.85, 0.1, 0.02)
    assert clamp_servo(inside, table) == inside
    assert clamp_servo(PelvisServo(0.5, -1.0, 1.0), table) == PelvisServo(
        low, -table.yaw_limit_rad, LATERAL_LIMIT_M)
    assert clamp_servo(PelvisServo(2.0, 1.0, -1.0), table) == PelvisServo(
        high, table.yaw_limit_rad, -LATERAL_LIMIT_M)
    assert table.yaw_limit_rad == pytest.approx(0.30)  # the hip yaws' 0.32 rad, less 0.02
