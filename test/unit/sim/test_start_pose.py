"""A start away from the origin and turned: the soles put on the world's ground under them
(not on z = 0), and everything that held the robot at the origin holding it there instead:
every reset, the start-up pin's weld, cmd_vel's warp height, the harness's height,
/atlas/sim_config."""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.course import parse_start
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.ground import Ground
from tutorial_atlas_control.sim.sim_config import SimConfig
from tutorial_atlas_control.sim.simulator import AtlasSimulator
from tutorial_atlas_control.sim.start_pose import sole_bottom_corners, start_line, start_pose
from tutorial_atlas_control.sim.vrc import CmdVelInput, ModeInput, PoseInput, VrcMode

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'
FLOOR = '<geom name="floor" type="plane" size="0 0 0.05"'
#: 3 m east, 2 m south, facing north (+y); the z is a hint the placement ignores.
TURNED = '3 -2 0.5 1.5707963267948966'
#: The raised plane's height (m): the VRC course's flat ground is at about z 0.03.
RAISED_M = 0.03


def variant(tmp_path: Path, floor: str) -> atlas_model.AtlasModel:
    """The package's model with its floor geom's opening tag replaced by `floor`."""
    text = atlas_model.MODEL_PATH.read_text()
    assert FLOOR in text
    path = tmp_path / 'atlas_variant.xml'
    path.write_text(text.replace(FLOOR, floor))
    return atlas_model.load_model(path)


@pytest.fixture(scope='module')
def flat() -> atlas_model.AtlasModel:
    return atlas_model.load_model()


@pytest.fixture
def raised(tmp_path: Path) -> atlas_model.AtlasModel:
    return variant(tmp_path, f'{FLOOR} pos="0 0 {RAISED_M}"')


def pelvis_yaw(quat: np.ndarray) -> float:
    w, _x, _y, z = quat
    return 2.0 * math.atan2(z, w)


@pytest.mark.parametrize('world, ground_m', [('flat', 0.0), ('raised', RAISED_M)])
def test_the_soles_stand_on_the_ground_under_the_start(
        world: str, ground_m: float, request: pytest.FixtureRequest) -> None:
    atlas = request.getfixturevalue(world)
    qpos = start_pose(atlas, parse_start(TURNED))
    data = mujoco.MjData(atlas.model)
    atlas_model.reset_to_initial(atlas, data, qpos)
    corners = sole_bottom_corners(atlas, data)
    np.testing.assert_allclose(corners[:, 2], ground_m, atol=1e-9)  # flat on it, not in it
    assert qpos[:2].tolist() == [3.0, -2.0]
    assert qpos[2] == pytest.approx(atlas_model.SPAWN_HEIGHT_M + ground_m, abs=1e-9)
    assert pelvis_yaw(qpos[3:]) == pytest.approx(math.pi / 2)
    # The soles turned with the pelvis: both along +y, the left one on the west (-x) side.
    left, right = corners[:4].mean(axis=0), corners[4:].mean(axis=0)
    assert left[0] < 3.0 < right[0]


def test_a_start_off_the_worlds_ground_is_one_error(tmp_path: Path) -> None:
    island = variant(tmp_path, '<geom name="floor" type="box" size="1 1 0.05" pos="0 0 -0.05"')
    with pytest.raises(atlas_model.ModelError,
                       match='^atlas_variant.xml has no ground under the soles at the start '
                             'x 10 m, y 0 m: give a start on its ground$'):
        AtlasSimulator(island, load_gains_yaml(CONFIG), start=parse_start('10 0 0 0'))


def run(sim: AtlasSimulator, seconds: float) -> None:
    for _ in range(int(round(seconds / sim.dt_s))):
        sim.step()


def test_resets_and_the_start_up_pin_hold_the_robot_at_the_start(
        raised: atlas_model.AtlasModel) -> None:
    """The port's start (pinned with gravity for 1 s): the weld holds the start's pose, not
    the model's spawn pose at the origin (which would drag the robot 3.6 m); a reset after a
    teleport puts it back there."""
    sim = AtlasSimulator(raised, load_gains_yaml(CONFIG), start=parse_start(TURNED))
    home = sim.start_qpos.copy()
    run(sim, 0.5)
    position, quat = atlas_model.pelvis_pose(sim.atlas, sim.data)
    assert sim.pinned
    np.testing.assert_allclose(position, home[:3], atol=1e-3)
    assert pelvis_yaw(quat) == pytest.approx(math.pi / 2, abs=1e-3)
    sim.apply_input(PoseInput((-5.0, 7.0, 2.0), (1.0, 0.0, 0.0, 0.0)))
    run(sim, 0.1)
    sim.reset_world()
    np.testing.assert_array_equal(sim.data.qpos[:7], home)
    assert sim.config().to_dict()['start'] == '3.0 -2.0 0.5 1.5707963267948966'
    assert SimConfig.from_json(sim.config().to_json()).start == '3.0 -2.0 0.5 1.5707963267948966'


def test_cmd_vel_warps_at_the_starts_height_and_the_harness_lifts_over_the_ground(
        raised: atlas_model.AtlasModel, flat: atlas_model.AtlasModel) -> None:
    sim = AtlasSimulator(raised, load_gains_yaml(CONFIG), start=parse_start(TURNED))
    sim.apply_input(CmdVelInput(0.5, 0.0, 0.0))
    run(sim, 0.2)
    position, _quat = atlas_model.pelvis_pose(sim.atlas, sim.data)
    assert position[2] == pytest.approx(sim.start_qpos[2], abs=1e-3)  # not 0.927 m
    assert position[1] > -2.0 + 0.09  # the pelvis's x axis points north
    sim.apply_input(CmdVelInput(0.0, 0.0, 0.0))
    sim.apply_input(ModeInput(VrcMode.HARNESSED))
    level = AtlasSimulator(flat, load_gains_yaml(CONFIG))
    level.apply_input(ModeInput(VrcMode.HARNESSED))
    assert (atlas_model.pelvis_height_m(sim.atlas, sim.data)
            == pytest.approx(atlas_model.pelvis_height_m(level.atlas, level.data) + RAISED_M))


def test_without_a_start_the_robot_spawns_as_the_model_says(flat: atlas_model.AtlasModel) -> None:
    sim = AtlasSimulator(flat, load_gains_yaml(CONFIG))
    np.testing.assert_array_equal(sim.data.qpos[:7], atlas_model.ORIGIN_PELVIS_QPOS)
    assert 'start' not in sim.config().to_dict()  # the default run's config text unchanged
    assert Ground(flat.model).level_m == 0.0


def test_the_start_line_says_where_the_pelvis_went(flat: atlas_model.AtlasModel) -> None:
    mud = parse_start('vrc_task_2_mud_start')
    assert start_line(mud, start_pose(flat, mud)) == (
        'start vrc_task_2_mud_start at x -0.290 m, y -23.020 m, yaw 90.0 deg: the pelvis at '
        'z 0.927 m puts the soles on the ground')
