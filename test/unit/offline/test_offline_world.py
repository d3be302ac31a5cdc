"""The world an offline run simulates: `run_offline.py --world NAME` (the course's model and
that world's start), `--start`, and a recorded run's model and start for replay and
`--asi-from`; each wrong one refused in one line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.bags import read_bag
from tutorial_atlas_control.cli.run_offline import main
from tutorial_atlas_control.course import STARTS, CourseError
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.offline import world as offline_world
from tutorial_atlas_control.offline.world import OfflineWorld, named_world, recorded_world
from tutorial_atlas_control.sim import MODEL_PATH, SimConfig


def config(model_file: str | None, start: str = '') -> SimConfig:
    return SimConfig(model_file, None, 0.001, 1.0, 0.0, start=start)


def test_a_world_is_the_courses_model_at_that_worlds_start(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / 'vrc_task_2.xml').write_text('<mujoco/>')
    monkeypatch.setattr(offline_world, 'package_path', lambda *parts: tmp_path.joinpath(*parts[1:]))
    world = named_world('vrc_task_2_uneven_start')
    assert world == OfflineWorld(tmp_path / 'vrc_task_2.xml', STARTS['vrc_task_2_uneven_start'])


def test_a_missing_course_model_or_an_unknown_world_is_one_line(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(offline_world, 'package_path', lambda *parts: tmp_path.joinpath(*parts))
    with pytest.raises(CourseError, match=f'^world vrc_task_2: the course model {tmp_path}/sim/'
                                          'vrc_task_2.xml is missing from the package$'):
        named_world('vrc_task_2')
    with pytest.raises(CourseError, match="^unknown world 'vrc_task_9'"):
        named_world('vrc_task_9')


def test_a_recorded_run_names_its_model_and_start() -> None:
    assert recorded_world(config('atlas_v1.xml')) == OfflineWorld(MODEL_PATH, None)
    mud = recorded_world(config('atlas_v1.xml', 'vrc_task_2_mud_start'))
    assert mud.start == STARTS['vrc_task_2_mud_start']
    # A model the package does not hold (a user's variant, a path): the default, whose
    # checksum replay then finds different.
    assert recorded_world(config('my_variant.xml')).model_path == MODEL_PATH
    assert recorded_world(config('../sim/atlas_v1.xml')).model_path == MODEL_PATH
    assert recorded_world(config(None)).model_path == MODEL_PATH
    with pytest.raises(CourseError, match="^the recorded /atlas/sim_config: start 'x y' has 2 "
                                          'values'):
        recorded_world(config('atlas_v1.xml', 'x y'))


@pytest.mark.parametrize('args, message', [
    (['--world', 'vrc_task_9'], "argument --world: unknown world 'vrc_task_9'; the VRC Task 2 "
                                'worlds are vrc_task_2, '),
    (['--start', '1 2 3'], "argument --start: start '1 2 3' has 3 values; give a start name or "
                           "'x y z yaw'"),
])
def test_run_offline_refuses_a_bad_world_or_start_on_its_command_line(
        args: list[str], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as stopped:
        main(['Traj_data2.yaml', 'touchdown', *args, '--bag', str(tmp_path / 'x.bag')])
    assert stopped.value.code == 2
    assert f'run_offline.py: error: {message}' in capsys.readouterr().err
    assert not (tmp_path / 'x.bag').exists()


def test_run_offline_starts_where_start_says(tmp_path: Path,
                                             capsys: pytest.CaptureFixture[str]) -> None:
    trajectory = tmp_path / 'short.yaml'
    trajectory.write_text('still:\n  - [0.1, "' + ' '.join(['0'] * NUM_JOINTS) + '"]\n')
    bag = tmp_path / 'turned.bag'
    assert main([str(trajectory), 'still', '--start', '3 -2 0 1.5707963267948966',
                 '--start-after', '1.1', '--settle', '0.2', '--bag', str(bag)]) == 0
    assert 'did not fall' in capsys.readouterr().out
    data = read_bag(bag)
    assert SimConfig.from_json(data.sim_configs[0][1]).start == '3.0 -2.0 0.0 1.5707963267948966'
    assert data.pelvis is not None
    np.testing.assert_allclose(data.pelvis.position_m[:, :2], [[3.0, -2.0]] * len(data.pelvis.t_s),
                               atol=0.02)  # where it started (1.2 cm of sway north at release)
    np.testing.assert_allclose(data.pelvis.orientation_xyzw[-1], [0, 0, 0.5 ** 0.5, 0.5 ** 0.5],
                               atol=0.01)
