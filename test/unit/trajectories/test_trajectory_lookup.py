"""Where traj_yaml.py finds YAML_FILE: the current directory, else the package's trajectories/."""

from __future__ import annotations

from pathlib import Path

import pytest

from tutorial_atlas_control.trajectories.trajectory import (
    TRAJECTORIES_DIR,
    TrajectoryError,
    is_explicit_path,
    load_trajectory,
    locate_trajectory_file,
    resolve_trajectory_file,
)


@pytest.fixture()
def dirs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[Path, Path]:
    """(current directory, package trajectories folder), each empty."""
    cwd, package = tmp_path / 'cwd', tmp_path / 'package_trajectories'
    cwd.mkdir()
    package.mkdir()
    monkeypatch.chdir(cwd)
    return cwd, package


def test_the_package_folder_holds_the_tutorial_file() -> None:
    assert (TRAJECTORIES_DIR / 'Traj_data2.yaml').is_file()


@pytest.mark.parametrize(('path', 'explicit'), [
    ('Traj.yaml', False), ('sub/Traj.yaml', False), ('./Traj.yaml', True),
    ('../Traj.yaml', True), ('/abs/Traj.yaml', True), ('.hidden.yaml', False)])
def test_explicit_paths(path: str, explicit: bool) -> None:
    assert is_explicit_path(path) is explicit


def test_a_file_in_the_current_directory_wins(dirs: tuple[Path, Path]) -> None:
    cwd, package = dirs
    (cwd / 'Traj.yaml').write_text('{}')
    (package / 'Traj.yaml').write_text('{}')
    assert resolve_trajectory_file('Traj.yaml', package) == ('Traj.yaml', False)


@pytest.mark.parametrize('name', ['Traj.yaml', 'sub/Traj.yaml'])
def test_a_bare_or_relative_name_falls_back_to_the_package(dirs: tuple[Path, Path],
                                                           name: str) -> None:
    _, package = dirs
    (package / name).parent.mkdir(exist_ok=True)
    (package / name).write_text('{}')
    assert resolve_trajectory_file(name, package) == (str(package / name), True)


@pytest.mark.parametrize('explicit', ['./Traj.yaml', '../cwd/Traj.yaml'])
def test_an_explicit_path_is_never_redirected(dirs: tuple[Path, Path], explicit: str) -> None:
    _, package = dirs
    (package / 'Traj.yaml').write_text('{}')
    assert resolve_trajectory_file(explicit, package) == (explicit, False)
    with pytest.raises(TrajectoryError, match=rf'^{explicit}: cannot read trajectory file: '
                                              r'No such file or directory$'):
        load_trajectory(explicit, 'step_and_fall')


def test_an_absolute_path_is_never_redirected(dirs: tuple[Path, Path]) -> None:
    cwd, package = dirs
    (package / 'Traj.yaml').write_text('{}')
    absent = str(cwd / 'Traj.yaml')
    assert resolve_trajectory_file(absent, package) == (absent, False)


def test_a_name_found_nowhere_is_one_line_naming_both_places(dirs: tuple[Path, Path]) -> None:
    _, package = dirs
    with pytest.raises(TrajectoryError) as caught:
        resolve_trajectory_file('absent.yaml', package)
    message = str(caught.value)
    assert '\n' not in message
    assert message.startswith('absent.yaml: cannot read trajectory file: No such file or directory')
    assert 'not in the current directory' in message and str(package) in message


def test_the_package_copy_is_announced_except_from_the_package_directory(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    package = tmp_path / 'package'
    (package / 'trajectories').mkdir(parents=True)
    (package / 'trajectories' / 'Traj.yaml').write_text('{}')
    (tmp_path / 'elsewhere').mkdir()
    (tmp_path / 'link').symlink_to(package)  # as the workspace's src/ link, where roscd lands
    found = str(package / 'trajectories' / 'Traj.yaml')
    for cwd, said in ((tmp_path / 'elsewhere',
                       [f'Traj.yaml is not in the current directory; using {found}']),
                      (package, []), (tmp_path / 'link', [])):
        monkeypatch.chdir(cwd)
        lines: list[str] = []
        assert locate_trajectory_file('Traj.yaml', lines.append, package / 'trajectories') == found
        assert lines == said, cwd
