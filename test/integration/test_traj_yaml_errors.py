"""traj_yaml.py's errors that need a ROS master, run as a user would: exit 1, one clear line,
nothing published on /atlas/joint_commands.

A private roscore (own port), no simulator: the gains and the timeout come from the
parameter server, the joint states never come.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

import rosgraph  # noqa: E402

from tutorial_atlas_control.demo import free_local_port, stop  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
TRAJ_YAML = REPO / 'scripts' / 'traj_yaml.py'
TRAJECTORIES = REPO / 'trajectories' / 'Traj_data2.yaml'
GAINS = REPO / 'config' / 'atlas_controller.yaml'
MASTER_TIMEOUT_S = 30.0


class Master:
    """A roscore of our own, and commands run against it."""

    def __init__(self, tmp_path: Path) -> None:
        port = free_local_port()
        self.env = dict(os.environ, ROS_MASTER_URI=f'http://localhost:{port}',
                        ROS_HOSTNAME='localhost', ROS_LOG_DIR=str(tmp_path / 'ros_log'))
        self.process = subprocess.Popen(['roscore', '-p', str(port)], env=self.env,
                                        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                        start_new_session=True)
        master = rosgraph.Master('/traj_yaml_errors_test', master_uri=self.env['ROS_MASTER_URI'])
        deadline = time.monotonic() + MASTER_TIMEOUT_S
        while True:
            try:
                master.getSystemState()
                return
            except OSError:
                assert time.monotonic() < deadline, 'roscore did not start'
                time.sleep(0.2)

    def run(self, *command: str, timeout_s: float = 60.0) -> subprocess.CompletedProcess:
        return subprocess.run(command, env=self.env, capture_output=True, text=True,
                              timeout=timeout_s, check=False)

    def traj_yaml(self, *ros_args: str) -> tuple[subprocess.CompletedProcess, str]:
        """Run the port on step_and_fall; return its result and what was published meanwhile."""
        echo = subprocess.Popen(['rostopic', 'echo', '/atlas/joint_commands/position'],
                                env=self.env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                text=True, start_new_session=True)
        try:
            time.sleep(1.0)  # rostopic echo registered before the port starts
            result = self.run(sys.executable, str(TRAJ_YAML), str(TRAJECTORIES),
                              'step_and_fall', *ros_args)
        finally:
            stop(echo, 'rostopic echo')
        return result, echo.stdout.read() if echo.stdout else ''


@pytest.fixture()
def master(tmp_path: Path) -> Iterator[Master]:
    core = Master(tmp_path)
    try:
        yield core
    finally:
        stop(core.process, 'roscore')


def refusal(master: Master, *ros_args: str) -> str:
    """Run the port; assert it exits 1 with one stderr line and publishes nothing; the line."""
    result, published = master.traj_yaml(*ros_args)
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert result.returncode == 1, result
    assert len(lines) == 1, lines
    assert 'Traceback' not in result.stderr
    assert published == '', f'published while refusing: {published[:200]}'
    return lines[0]


def test_missing_gains_name_the_parameter_and_how_to_load_it(master: Master) -> None:
    line = refusal(master)
    assert 'parameter atlas_controller/gains is not set' in line
    assert 'roslaunch tutorial_atlas_control atlas.launch' in line
    assert 'rosparam load' in line


def test_non_numeric_gain_is_named(master: Master) -> None:
    assert master.run('rosparam', 'load', str(GAINS)).returncode == 0
    assert master.run('rosparam', 'set', '/atlas_controller/gains/l_arm_elx/p',
                      'fast').returncode == 0
    assert 'atlas_controller/gains/l_arm_elx/p' in refusal(master)


def test_no_simulator_times_out_with_a_hint(master: Master) -> None:
    assert master.run('rosparam', 'load', str(GAINS)).returncode == 0
    line = refusal(master, '_joint_state_timeout:=1.5')
    assert 'no simulator is publishing /atlas/joint_states' in line
    assert 'atlas.launch' in line
    assert 'within 1.5 s' in line, 'the ~joint_state_timeout parameter was not used'


def test_bad_timeout_parameter_is_named(master: Master) -> None:
    assert master.run('rosparam', 'load', str(GAINS)).returncode == 0
    line = refusal(master, '_joint_state_timeout:=-1')
    assert '~joint_state_timeout' in line and 'positive number of seconds' in line
