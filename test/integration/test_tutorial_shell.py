"""The tutorial's command lines, typed as a new user would: a fresh `bash -i`, `source ./env.sh`.

Each shell starts from a bare environment (PATH of the system, an empty HOME, no ROS
variables but a private ROS_MASTER_URI), so what works here works because env.sh set it up:
`roscd` (Debian's rosbash functions), `rosrun tutorial_atlas_control traj_yaml.py
Traj_data2.yaml step_and_fall` from the package directory (the file is found in
trajectories/), and an explicit path that does not exist refused in one line, exit 1.

Needs `make setup` (the workspace) and roslaunch; about 60 s of wall time.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

if shutil.which('roslaunch') is None or 'TAC_HOME' not in os.environ:
    pytest.skip('needs the project environment (source env.sh)', allow_module_level=True)
pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from tutorial_atlas_control.processes import free_local_port, stop_tree

REPO = Path(__file__).resolve().parents[2]
TRAJECTORY_FILE = REPO / 'trajectories' / 'Traj_data2.yaml'
#: Lines bash -i prints on stderr when it has no terminal (not the commands' output).
BASH_NOISE = ('bash: cannot set terminal process group', 'bash: no job control in this shell')
FALLEN_BELOW_M = 0.5
#: Wall-clock bounds (s).
SHELL_TIMEOUT_S = 180.0
STARTUP_TIMEOUT_S = 60.0
FALL_TIMEOUT_S = 60.0
#: Sim time (s) the simulator runs before the tutorial's steps: the torso is pinned for 1 s.
START_SETTLE_S = 1.5


def fresh_env(home: Path, master_uri: str) -> dict[str, str]:
    return {
        'HOME': str(home), 'PATH': '/usr/local/bin:/usr/bin:/bin', 'TERM': 'dumb',
        'LANG': os.environ.get('LANG', 'C.UTF-8'),
        # this clone's virtualenv and workspace (tools/paths.sh keys them under $HOME)
        'TAC_CACHE_DIR': str(Path(os.environ['TAC_HOME']).parent),
        'ROS_MASTER_URI': master_uri, 'ROS_LOG_DIR': str(home / 'ros_log'),
    }


def bash_i(script: str, env: dict[str, str], cwd: Path = REPO) -> subprocess.CompletedProcess[str]:
    """`script` in a fresh interactive bash, after `source ./env.sh` from the repository."""
    return subprocess.run(['bash', '-i', '-c', f'source ./env.sh || exit 1\n{script}'], cwd=cwd,
                          env=env, capture_output=True, text=True, timeout=SHELL_TIMEOUT_S,
                          check=False,
                          stdin=subprocess.DEVNULL)


def stderr_lines(result: subprocess.CompletedProcess[str]) -> list[str]:
    return [line for line in result.stderr.splitlines() if not line.startswith(BASH_NOISE)]


@pytest.fixture()
def home(tmp_path: Path) -> Path:
    path = tmp_path / 'home'
    path.mkdir()
    return path


def test_roscd_goes_to_the_package(home: Path) -> None:
    env = fresh_env(home, 'http://localhost:11311')
    result = bash_i('type -t roscd rosls rosed roscp && complete -p rosrun roslaunch rostopic '
                    '&& roscd tutorial_atlas_control && pwd && rospack find tutorial_atlas_control',
                    env, cwd=REPO)
    assert result.returncode == 0, result
    lines = result.stdout.splitlines()
    assert lines[:4] == ['function'] * 4
    assert [line.split()[-1] for line in lines[4:7]] == ['rosrun', 'roslaunch', 'rostopic']
    pwd, package = lines[-2:]
    assert pwd == package  # roscd lands where rospack finds the package...
    assert Path(pwd).resolve() == REPO  # ...which is this clone
    assert stderr_lines(result) == []


def test_missing_explicit_path_is_refused_in_one_line(home: Path) -> None:
    env = fresh_env(home, 'http://localhost:11311')
    result = bash_i('roscd tutorial_atlas_control && '
                    'rosrun tutorial_atlas_control traj_yaml.py ./Traj_data2.yaml step_and_fall; '
                    'echo "exit status $?"', env)
    assert result.stdout.splitlines()[-1] == 'exit status 1'
    assert stderr_lines(result) == [
        './Traj_data2.yaml: cannot read trajectory file: No such file or directory']


@pytest.fixture()
def simulator(tmp_path: Path, home: Path) -> Iterator[dict[str, str]]:
    """atlas.launch (headless, no recording) on a private master; the shell's environment."""
    port = free_local_port()
    env = fresh_env(home, f'http://localhost:{port}')
    log = open(tmp_path / 'atlas_launch.log', 'w')  # noqa: SIM115 - closed below
    launch = subprocess.Popen(
        ['bash', '-c', f'source ./env.sh && exec roslaunch -p {port} tutorial_atlas_control '
         'atlas.launch gui:=false record:=false'],
        cwd=REPO, env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        deadline = time.monotonic() + STARTUP_TIMEOUT_S
        while sim_time_s(env) < START_SETTLE_S:
            assert launch.poll() is None, f'atlas.launch exited; see {log.name}'
            assert time.monotonic() < deadline, f'no /clock past {START_SETTLE_S} s; see {log.name}'
        yield env
    finally:
        stop_tree(launch)
        log.close()


def echo(env: dict[str, str], field: str) -> str:
    result = subprocess.run(['bash', '-c', f'source ./env.sh && rostopic echo -n1 {field}'],
                            cwd=REPO, env=env, capture_output=True, text=True, timeout=30,
                            check=False)
    return result.stdout.split('\n', 1)[0] if result.returncode == 0 else ''


def sim_time_s(env: dict[str, str]) -> float:
    text = echo(env, '/clock/clock/secs')
    return float(text) if text.strip().isdigit() else 0.0


def test_tutorial_step_and_fall_from_the_package_directory(simulator: dict[str, str]) -> None:
    env = simulator
    result = bash_i(
        'rostopic pub /atlas/control_mode std_msgs/String -- "User" > /dev/null &\n'
        'roscd tutorial_atlas_control\n'
        'rosrun tutorial_atlas_control traj_yaml.py Traj_data2.yaml step_and_fall\n'
        'status=$?; kill %1; echo "exit status $status"', env)
    lines = result.stdout.splitlines()
    assert lines[-1] == 'exit status 0', result
    # roscd lands in the package: its trajectories/ is where the file is expected, unsaid.
    assert not [line for line in lines if 'not in the current directory' in line], lines
    deadline = time.monotonic() + FALL_TIMEOUT_S
    heights = []
    while time.monotonic() < deadline:
        text = echo(env, '/ground_truth_odom/pose/pose/position/z')
        if text:
            heights.append(float(text))
            if heights[-1] < FALLEN_BELOW_M:
                break
    assert heights and heights[-1] < FALLEN_BELOW_M, f'the robot did not fall: pelvis {heights}'


def test_posix_sh_says_what_it_misses(home: Path) -> None:
    """In a shell other than bash env.sh sets ROS up and says, in one line, what it cannot give."""
    env = fresh_env(home, 'http://localhost:11311')
    result = subprocess.run(
        ['sh', '-c', '. ./env.sh; echo "env.sh status $?"; rospack find tutorial_atlas_control'],
        cwd=REPO, env=env, capture_output=True, text=True, timeout=SHELL_TIMEOUT_S, check=False)
    assert result.stdout.splitlines()[0] == 'env.sh status 0'
    assert Path(result.stdout.splitlines()[1]).resolve() == REPO
    assert result.stderr.splitlines() == [
        "env.sh: no roscd/rosls/rosed/roscp or ROS tab completion in this shell: they are bash "
        "functions (Debian's rosbash); ROS itself is set up"]
