"""Walk on a slope follows its feet (walking/feet_surfaces.py, swing.py): the CoM height over
the mean of the feet's surfaces, moving with each step's z over the step; the swing's apex
clear of the higher end; the sole laid on its surface's normal. On level ground every new
term vanishes exactly (the flat walks' figures are the same bits)."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from support.standing import started_stand
from tutorial_atlas_control.balance import StandBehaviour, place_on_slope, slope_model
from tutorial_atlas_control.sim import Ground
from tutorial_atlas_control.walking import straight_steps
from tutorial_atlas_control.walking.feet_surfaces import FeetSurfaces, support_height_m
from tutorial_atlas_control.walking.footsteps import Footstep
from tutorial_atlas_control.walking.leg_tasks import foot_pose
from tutorial_atlas_control.walking.phases import swing_to
from tutorial_atlas_control.walking.step_queue import StepQueue
from tutorial_atlas_control.walking.swing import (
    END_CLEARANCE_M,
    SWING_HEIGHT_M,
    SwingPath,
    sole_frame,
    surface_tilt,
    swing_height_m,
)
from tutorial_atlas_control.walking.walk import WalkController

SLOPE = math.radians(16.0)
#: A surface rising along +x by SLOPE: its upward normal.
NORMAL = (-math.sin(SLOPE), 0.0, math.cos(SLOPE))


def test_the_support_height_is_the_feet_s_mean_and_moves_over_each_step() -> None:
    assert support_height_m(0.1, 0.3) == pytest.approx(0.2)
    surfaces = FeetSurfaces((0.0, 0.0))
    assert not surfaces.step(0, 0.0, 1.0, 0.5)  # level: nothing moves
    assert surfaces.over_feet_m(0.86) == 0.86  # exactly: the flat walk's bits
    assert surfaces.step(0, 0.1, 1.0, 0.5)  # the left foot 0.1 m up
    assert surfaces.rise_m == pytest.approx(0.05)
    assert surfaces.over_feet_m(0.86) == pytest.approx(0.91)
    assert surfaces.support_at(1.0) == pytest.approx(0.0)  # from where it was ...
    assert surfaces.support_at(1.25) == pytest.approx(0.025)  # ... halfway at mid-step ...
    assert surfaces.support_at(1.5) == pytest.approx(0.05)  # ... there at the step's end
    assert surfaces.support_at(9.0) == pytest.approx(0.05)
    assert surfaces.step(1, 0.2, 2.0, 0.5)
    assert surfaces.support_at(2.5) == pytest.approx(0.15)


def test_the_swing_clears_the_higher_end_and_is_unchanged_on_level_ground() -> None:
    assert swing_height_m(0.0003, 0.0) == SWING_HEIGHT_M  # level (the sole's mm): as before
    assert swing_height_m(0.0, 0.056) == SWING_HEIGHT_M  # 0.4 m up 8 degrees: the line's 8 cm
    for start, end in ((0.0, 0.2), (0.3, 0.05)):  # a ramp's 0.2 m, a block's 0.25 m
        path = SwingPath(np.zeros(3), np.array([0.4, 0.0, end]), 0.0, 0.0, 0.6,
                         swing_height_m(start, end))
        path = SwingPath(np.array([0.0, 0.0, start]), path.end, 0.0, 0.0, 0.6, path.height_m)
        apex = path.at(0.3)[0][2]
        assert apex == pytest.approx(max(start, end) + END_CLEARANCE_M)


def test_a_sole_is_laid_on_its_surface_s_normal() -> None:
    assert surface_tilt((0.0, 0.0, 1.0)) == (0.0, 0.0)
    assert np.array_equal(sole_frame(0.3, (0.0, 0.0))[2], [0.0, 0.0, 1.0])
    for yaw in (0.0, 0.7, -2.5):
        frame = sole_frame(yaw, surface_tilt(NORMAL))
        assert frame[:, 2] == pytest.approx(NORMAL, abs=1e-12)  # its z on the normal
        assert frame.T @ frame == pytest.approx(np.eye(3), abs=1e-12)
        heading = math.atan2(frame[1, 0], frame[0, 0])
        assert heading == pytest.approx(yaw, abs=0.05)  # still facing its yaw


def test_a_swing_turns_the_sole_from_its_surface_to_the_landing_s() -> None:
    _, _, stand = started_stand()
    state = stand.last_state
    assert state is not None
    step = Footstep(1, 0, 0.5, 0.12, 0.0, z_m=0.5 * math.tan(SLOPE), normal=NORMAL)
    path = swing_to(state, step, 0.5)
    assert path.tilt(0.0) == (0.0, 0.0)  # lifted from the level floor
    assert path.tilt(0.5) == pytest.approx(surface_tilt(NORMAL))
    assert path.height_m > SWING_HEIGHT_M  # 0.14 m up: the apex 3 cm over the landing


def test_the_walk_s_com_height_follows_a_step_up() -> None:
    atlas, data, stand = started_stand()
    state, controller = stand.last_state, stand.controller
    assert state is not None and controller is not None
    queue = StepQueue(foot_pose(state, 0), foot_pose(state, 1))
    rise = 0.25 * math.tan(SLOPE)
    queue.offer([Footstep(s.step_index, s.foot_index, s.x_m, s.y_m, s.yaw_rad, s.duration_s,
                          z_m=s.x_m * math.tan(SLOPE), normal=NORMAL)
                 for s in straight_steps(2, 0.25)])
    walk = WalkController(controller, queue, state, 0.0, surfaces_m=(0.0, 0.0))
    sway_end = walk.gains.sway_s
    before = walk.legs.height(sway_end)[0]
    walk.tick_torque(state, data.qpos[atlas.qpos_adr], data.qvel[atlas.dof_adr], sway_end)
    assert walk.step is not None and walk.step.step_index == 1  # the first step under way
    duration = walk.step.duration_s
    # Over the first step the reference rises by half the step's rise (one foot up, one not).
    assert walk.legs.height(sway_end + duration)[0] == pytest.approx(before + rise / 2)
    assert walk.surfaces.support_at(sway_end + duration) == pytest.approx(rise / 2)


def test_a_walk_starts_on_the_ground_under_its_soles() -> None:
    _, _, level = started_stand()
    assert level.last_state is not None
    assert level.ground_under_soles(level.last_state) == ((0.0, (0.0, 0.0, 1.0)),) * 2
    slope = math.radians(8.0)
    atlas = slope_model(slope)
    data = mujoco.MjData(atlas.model)
    place_on_slope(atlas, data, slope, Ground(atlas.model))
    stand = StandBehaviour(atlas)
    stand.start(data)
    assert stand.last_state is not None
    for (height, normal), centre in zip(stand.ground_under_soles(stand.last_state),
                                        stand.last_state.sole_centres, strict=True):
        assert height == pytest.approx(centre[0] * math.tan(slope), abs=1e-9)
        assert normal == pytest.approx((-math.sin(slope), 0.0, math.cos(slope)), abs=1e-9)
