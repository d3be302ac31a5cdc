"""The VRC Task 2 launches as roslaunch reads them (no master): each includes atlas.launch
with the course's model, its world's start, DRCSim's bdi_stand start and the scorer on,
and starts course_markers.py on the same model (rviz's course; course_markers:=false not);
DRCSim's gzname chooses the viewer, a bad one stops the launch with its reason; every
argument of atlas.launch reaches through; roslaunch's own check (roslaunch-check) passes."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path
from typing import Any

import pytest

from tutorial_atlas_control.course import STARTS

config = pytest.importorskip('roslaunch.config', reason='needs ROS: source ./env.sh')
rlutil = pytest.importorskip('roslaunch.rlutil', reason='needs ROS: source ./env.sh')

LAUNCH_DIR = Path(__file__).resolve().parents[2] / 'launch'
#: Each launch and the start it gives (DRCSim's world of the same name).
LAUNCHES = {f'{name}.launch': name for name in STARTS}


def params(launch: str, *args: str, display: str | None = None,
           monkeypatch: pytest.MonkeyPatch) -> tuple[dict[str, Any], list[str]]:
    """The parameters and node types `roslaunch launch args` would set and start."""
    if display is None:
        monkeypatch.delenv('DISPLAY', raising=False)
    else:
        monkeypatch.setenv('DISPLAY', display)
    loaded = config.load_config_default([(str(LAUNCH_DIR / launch), list(args))], None)
    return ({name: param.value for name, param in loaded.params.items()},
            [node.type for node in loaded.nodes])


@pytest.mark.parametrize('launch, start', LAUNCHES.items())
def test_each_launch_starts_its_world_as_drcsim_did(
        launch: str, start: str, monkeypatch: pytest.MonkeyPatch) -> None:
    found, nodes = params(launch, monkeypatch=monkeypatch)
    assert found['/atlas_sim/model_file'].endswith('/sim/vrc_task_2.xml')
    assert found['/atlas_sim/start'] == start
    assert found['/atlas/startup_mode'] == 'bdi_stand'
    assert found['/atlas_sim/vrc_scoring'] is True
    assert found['/atlas_sim/score_dir'] == '/tmp/vrc_task_2'
    assert found['/atlas_sim/gui'] is False  # no display
    assert sorted(nodes) == ['atlas_sim_node.py', 'course_markers.py', 'multisense_cameras.py',
                             'record_run.sh']
    assert rlutil.check_roslaunch(str(LAUNCH_DIR / launch)) is None  # roslaunch-check


@pytest.mark.parametrize('args, display, gui', [
    ((), ':0', True),                      # DRCSim's default, gazebo: the viewer
    (('gzname:=gazebo',), None, False),    # no display: headless, as atlas.launch
    (('gzname:=gzserver',), ':0', False),  # DRCSim's headless server
    (('gzname:=gzserver', 'gui:=true'), ':0', True),  # gui given wins
])
def test_gzname_chooses_the_viewer(args: tuple[str, ...], display: str | None, gui: bool,
                                   monkeypatch: pytest.MonkeyPatch) -> None:
    for launch in ('vrc_task_2.launch', 'vrc_task_2_uneven_start.launch'):
        found, _nodes = params(launch, *args, display=display, monkeypatch=monkeypatch)
        assert found['/atlas_sim/gui'] is gui


def test_a_bad_gzname_stops_the_launch_saying_why() -> None:
    result = subprocess.run(
        ['roslaunch', '--nodes', str(LAUNCH_DIR / 'vrc_task_2_mud_start.launch'),
         'gzname:=gzclient'], capture_output=True, text=True, timeout=60,
        env={**os.environ, 'ROS_HOME': os.environ.get('ROS_HOME', '/tmp')})
    assert result.returncode == 1
    assert ('Invalid <arg> tag: gzname:=gzclient is neither gazebo (with the viewer) nor '
            'gzserver (headless).') in result.stderr
    assert 'Traceback' not in result.stderr and result.stdout == ''


def test_atlas_launch_arguments_reach_through_and_a_variant_keeps_its_start(
        monkeypatch: pytest.MonkeyPatch) -> None:
    found, nodes = params('vrc_task_2_rubble_start.launch', 'record:=false',
                          'real_time_factor:=0.5', 'score_dir:=/tmp/scores', 'stand:=hold',
                          'start:=vrc_task_2', 'model:=/tmp/course.xml', 'cameras:=false',
                          monkeypatch=monkeypatch)
    assert nodes == ['atlas_sim_node.py', 'course_markers.py']
    assert '/atlas_sim/bag_dir' not in found
    assert found['/atlas_sim/real_time_factor'] == 0.5
    assert found['/atlas_sim/score_dir'] == '/tmp/scores'
    assert found['/atlas_sim/stand'] == 'hold'
    assert found['/atlas_sim/model_file'] == '/tmp/course.xml'
    assert found['/atlas_sim/start'] == 'vrc_task_2_rubble_start'
    found, _nodes = params('vrc_task_2.launch', 'start:=1 2 0 1.57', 'startup_mode:=pinned',
                           monkeypatch=monkeypatch)
    assert found['/atlas_sim/start'] == '1 2 0 1.57'
    assert found['/atlas/startup_mode'] == 'pinned'


def test_atlas_launch_passes_its_start(monkeypatch: pytest.MonkeyPatch) -> None:
    found, _nodes = params('atlas.launch', monkeypatch=monkeypatch)
    assert found['/atlas_sim/start'] == ''
    assert '/atlas_sim/vrc_scoring' not in found
    found, _nodes = params('atlas.launch', 'start:=vrc_task_2_mud_start', monkeypatch=monkeypatch)
    assert found['/atlas_sim/start'] == 'vrc_task_2_mud_start'


def test_the_course_markers_follow_the_model_and_can_be_left_out(
        monkeypatch: pytest.MonkeyPatch) -> None:
    loaded = config.load_config_default(
        [(str(LAUNCH_DIR / 'vrc_task_2_mud_start.launch'), ['model:=/tmp/course.xml'])], None)
    (markers,) = [node for node in loaded.nodes if node.type == 'course_markers.py']
    assert markers.args == '/tmp/course.xml' and markers.name == 'course_markers'
    _found, nodes = params('vrc_task_2.launch', 'course_markers:=false', monkeypatch=monkeypatch)
    assert 'course_markers.py' not in nodes
