"""state_publisher.py's start-up decisions (the exec of robot_state_publisher is left to the
rostest tf.test)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from tutorial_atlas_control.cli import state_publisher as state_publisher_cli
from tutorial_atlas_control.sim import model
from tutorial_atlas_control.sim import state_publisher_node as state_publisher


def test_usage_without_a_model_file(capsys: pytest.CaptureFixture[str]) -> None:
    assert state_publisher_cli.main(['state_publisher.py', '__name:=rsp']) == 1
    assert 'usage: state_publisher.py MODEL_FILE' in capsys.readouterr().err


def test_a_model_without_urdf_starts_nothing_and_exits_0(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    variant = tmp_path / 'variant.xml'
    shutil.copy(model.MODEL_PATH, variant)
    assert state_publisher_cli.main(['state_publisher.py', str(variant), '__name:=rsp']) == 0
    out = capsys.readouterr().out
    assert f'robot_state_publisher not started: the model {variant} has no URDF beside it' in out


def test_robot_state_publisher_is_found() -> None:
    pytest.importorskip('roslib')
    path = Path(state_publisher.robot_state_publisher_executable())
    assert path.name == 'robot_state_publisher' and path.is_file()

