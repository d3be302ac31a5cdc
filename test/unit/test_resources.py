"""resources: the package data and the vendored .msg files, in a source tree and an install."""

from __future__ import annotations

from pathlib import Path

import pytest

from tutorial_atlas_control import resources

REPO = Path(__file__).resolve().parents[2]


def test_source_tree_data_and_message_file() -> None:
    assert resources.package_dir() == REPO
    assert resources.package_path('sim', 'atlas_v1.xml').is_file()
    assert resources.message_file('osrf_msgs', 'JointCommands') == (
        REPO / 'msg' / 'osrf_msgs' / 'msg' / 'JointCommands.msg')


def _install_space(tmp_path: Path) -> Path:
    """An install prefix's layout: code under lib/python3/dist-packages, data under share/."""
    module_dir = tmp_path / 'lib' / 'python3' / 'dist-packages' / resources.PACKAGE_NAME
    module_dir.mkdir(parents=True)
    share = tmp_path / 'share'
    (share / resources.PACKAGE_NAME).mkdir(parents=True)
    (share / resources.PACKAGE_NAME / 'package.xml').write_text(
        f'<package><name>{resources.PACKAGE_NAME}</name></package>')
    (share / 'osrf_msgs' / 'msg').mkdir(parents=True)
    (share / 'osrf_msgs' / 'msg' / 'JointCommands.msg').write_text('float64[] position\n')
    return module_dir


def test_install_space_data_and_message_file(tmp_path: Path,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(resources, '_MODULE_DIR', _install_space(tmp_path))
    assert resources.package_dir() == tmp_path / 'share' / resources.PACKAGE_NAME
    assert resources.message_file('osrf_msgs', 'JointCommands') == (
        tmp_path / 'share' / 'osrf_msgs' / 'msg' / 'JointCommands.msg')


def test_missing_data_and_message_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    module_dir = tmp_path / 'a' / 'b' / 'c' / resources.PACKAGE_NAME
    module_dir.mkdir(parents=True)
    monkeypatch.setattr(resources, '_MODULE_DIR', module_dir)
    monkeypatch.setenv('ROS_PACKAGE_PATH', str(tmp_path))
    with pytest.raises(resources.AtlasControlError, match='cannot find the tutorial_atlas_control'):
        resources.package_dir()
    assert resources.message_file('osrf_msgs', 'NoSuchMessage') is None
