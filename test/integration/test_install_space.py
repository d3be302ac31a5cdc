"""The tutorial from a catkin install space: built, installed, run, and its bag read.

The workspace is not the developer's: `make setup` builds one beside it
(tools/build_install_space.sh: src/ holds symlinks to this repository and its two message
packages), from a bare environment, so nothing of the developer's workspace (devel space,
build directory) can hide a missing install rule. Here it is rebuilt (only what changed
compiles) and installed into an emptied prefix, so that a file no install rule names any
more cannot linger there. The commands, as a user would type them:

    mkdir -p WS/src && cd WS/src && ln -s REPO tutorial_atlas_control \\
        && ln -s REPO/msg/osrf_msgs osrf_msgs && ln -s REPO/msg/atlas_msgs atlas_msgs
    cd WS && catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 \\
        -DPython3_EXECUTABLE=/usr/bin/python3 -DCATKIN_ENABLE_TESTING=OFF \\
        -DCMAKE_INSTALL_PREFIX=PREFIX install
    # a new shell, bare environment: only the prefix, plus the virtualenv's site-packages
    # (mujoco, rosbags: PyPI packages without a catkin or Debian install) after it
    source PREFIX/setup.bash
    export PYTHONPATH="$PYTHONPATH:$($TAC_VENV/bin/python -c \\
        'import sysconfig; print(sysconfig.get_paths()["purelib"])')"
    roslaunch -p PORT tutorial_atlas_control atlas.launch gui:=false bag_dir:=BAGS &
    rostopic pub -1 /atlas/control_mode std_msgs/String -- User
    cd ELSEWHERE && rosrun tutorial_atlas_control traj_yaml.py Traj_data2.yaml touchdown
    kill -INT %1
    rosrun tutorial_atlas_control analyze_bag.py BAGS/atlas_*.bag --json

Judged: the robot stays up through touchdown, whose arm joints moved; and what ran came
from PREFIX (the environment names neither the repository nor the developer's workspace,
the package's Python, its data, its node and its compiled library are PREFIX's).
Needs `make setup` (Debian's catkin and ROS, the virtualenv, the install workspace).
"""

from __future__ import annotations

import fcntl
import json
import os
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

if shutil.which('roslaunch') is None or shutil.which('catkin_make') is None \
        or 'TAC_INSTALL_WS' not in os.environ:
    pytest.skip('needs the project environment (make setup, source env.sh)',
                allow_module_level=True)

from support.launch import TestLaunch
from tutorial_atlas_control.native import LIBRARY_NAME

REPO = Path(__file__).resolve().parents[2]
PACKAGE = 'tutorial_atlas_control'
BUILD_SCRIPT = REPO / 'tools' / 'build_install_space.sh'
#: A bare shell's PATH: ROS's commands are Debian's, in /usr/bin.
BARE_PATH = '/usr/local/bin:/usr/bin:/bin'
#: Variables whose entries must not lead back to the source tree or the developer's workspace.
PATH_VARIABLES = ('PATH', 'PYTHONPATH', 'CMAKE_PREFIX_PATH', 'ROS_PACKAGE_PATH',
                  'LD_LIBRARY_PATH', 'PKG_CONFIG_PATH')
#: Wall-clock guards (s) against hangs, far beyond what each step takes.
BUILD_TIMEOUT_S = 900.0
COMMAND_TIMEOUT_S = 60.0
TRAJECTORY_TIMEOUT_S = 180.0
#: Sim time (s) before User: the torso is pinned for the first 1 s.
START_SETTLE_S = 1.5
#: Sim time (s) the robot is left alone after touchdown, before Ctrl-C.
END_SETTLE_S = 2.0
#: Pelvis height (m) the robot stays above when standing (it is about 0.9 m).
UPRIGHT_ABOVE_M = 0.7
#: The joints touchdown moves (its arms).
TOUCHDOWN_JOINTS = ('l_arm_elx', 'r_arm_elx', 'l_arm_shx', 'r_arm_shx')


def bare_env(home: Path) -> dict[str, str]:
    return {'HOME': str(home), 'PATH': BARE_PATH, 'LANG': os.environ.get('LANG', 'C.UTF-8')}


def venv_site_packages() -> str:
    """The project virtualenv's site-packages, as env.sh finds it."""
    return subprocess.run(
        [str(Path(os.environ['TAC_VENV']) / 'bin' / 'python'), '-c',
         'import sysconfig; print(sysconfig.get_paths()["purelib"])'],
        capture_output=True, text=True, check=True).stdout.strip()


def build_install_space(workspace: Path, prefix: Path) -> None:
    """tools/build_install_space.sh: `catkin_make install` into an emptied `prefix`."""
    result = subprocess.run(['bash', str(BUILD_SCRIPT), str(workspace), str(prefix)],
                            capture_output=True, text=True, timeout=BUILD_TIMEOUT_S, check=False)
    assert result.returncode == 0, f'catkin_make install failed:\n{result.stderr}'


def install_env(prefix: Path, home: Path) -> dict[str, str]:
    """The environment of a new shell that sourced only `prefix`'s setup.bash (and put the
    virtualenv's site-packages after it on PYTHONPATH)."""
    script = (f'source {prefix}/setup.bash && '
              f'export PYTHONPATH="$PYTHONPATH:{venv_site_packages()}" && env -0')
    result = subprocess.run(['bash', '-c', script], env=bare_env(home), capture_output=True,
                            check=True, timeout=COMMAND_TIMEOUT_S)
    return dict(entry.split('=', 1) for entry in result.stdout.decode().split('\0') if entry)


def run(env: dict[str, str], *command: str, cwd: Path | None = None,
        timeout_s: float = COMMAND_TIMEOUT_S) -> subprocess.CompletedProcess[str]:
    return subprocess.run(command, env=env, cwd=cwd, capture_output=True, text=True,
                          timeout=timeout_s, check=False)


def within(path: str | Path, directory: Path) -> bool:
    return Path(path).resolve().is_relative_to(directory.resolve())


@pytest.fixture()
def install_space() -> Iterator[tuple[Path, Path]]:
    """The install workspace and its prefix, rebuilt, held against any other pytest's use."""
    workspace, prefix = Path(os.environ['TAC_INSTALL_WS']), Path(os.environ['TAC_INSTALL_PREFIX'])
    workspace.mkdir(parents=True, exist_ok=True)
    with (workspace.parent / 'install_ws.lock').open('w') as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        build_install_space(workspace, prefix)
        yield workspace, prefix


def test_the_tutorial_runs_from_an_install_space(
        tmp_path: Path, install_space: tuple[Path, Path]) -> None:
    home = tmp_path / 'home'
    home.mkdir()
    workspace, prefix = install_space
    env = install_env(prefix, home)
    share = prefix / 'share' / PACKAGE

    # Nothing in the environment leads to the source tree or the developer's workspace.
    developer = [REPO, Path(os.environ.get('TAC_WS', REPO)), workspace]
    leaks = [entry for name in PATH_VARIABLES for entry in env.get(name, '').split(':')
             if entry and any(within(entry, place) for place in developer)]
    assert leaks == []
    where = run(env, 'python3', '-c', 'import osrf_msgs.msg, tutorial_atlas_control as t; '
                'print(t.__file__); print(osrf_msgs.msg.__file__)')
    assert where.returncode == 0, where.stderr
    assert all(within(line, prefix / 'lib') for line in where.stdout.split()), where.stdout
    found = run(env, 'rospack', 'find', PACKAGE)
    assert found.stdout.strip() == str(share), found
    # The installed echo_controller runs from the prefix: its usage on stdout, exit 0.
    echo = run(env, 'rosrun', PACKAGE, 'echo_controller', '--help')
    assert (echo.returncode, echo.stdout.splitlines()[0]) == (
        0, 'usage: echo_controller [--transport tcp|udp|udp-then-tcp] [--period-ms N]'), echo
    assert (prefix / 'lib' / PACKAGE / 'echo_controller').is_file()

    with TestLaunch(tmp_path, base_env=env) as launch:
        launch.wait_ready()
        simulator = launch.pid_of('atlas_sim_node.py')
        command_line = Path(f'/proc/{simulator}/cmdline').read_bytes().split(b'\0')
        assert str(prefix / 'lib' / PACKAGE / 'atlas_sim_node.py').encode() in command_line
        library = prefix / 'lib' / LIBRARY_NAME
        assert str(library) in Path(f'/proc/{simulator}/maps').read_text(), \
            f'the simulator has not loaded {library}:\n{launch.output()}'
        launch.wait_sim_until(START_SETTLE_S)
        launch.set_mode('User')
        elsewhere = tmp_path / 'elsewhere'  # no Traj_data2.yaml here: the installed one
        elsewhere.mkdir()
        played = run(launch.env, 'rosrun', PACKAGE, 'traj_yaml.py', 'Traj_data2.yaml',
                     'touchdown', cwd=elsewhere, timeout_s=TRAJECTORY_TIMEOUT_S)
        assert played.returncode == 0, played.stdout + played.stderr
        installed_file = share / 'trajectories' / 'Traj_data2.yaml'
        assert (f'Traj_data2.yaml is not in the current directory; using {installed_file}'
                in played.stdout.splitlines()), played.stdout
        launch.wait_sim_s(END_SETTLE_S)
        launch.interrupt()
        output = launch.output()
    assert 'using the numpy' not in output, output  # no fallback: the library loaded
    bag = launch.bag()

    analysed = run(env, 'rosrun', PACKAGE, 'analyze_bag.py', str(bag), '--json')
    assert analysed.returncode == 0, analysed.stderr
    summary = json.loads(analysed.stdout)
    assert summary['trajectory']['name'] == 'touchdown'
    assert [entry['mode'] for entry in summary['mode_timeline']][-1] == 'User'
    assert summary['fell'] is False and summary['min_pelvis_height'] > UPRIGHT_ABOVE_M
    assert set(TOUCHDOWN_JOINTS) <= set(summary['joints'])
    assert summary['command_count'] > 0
