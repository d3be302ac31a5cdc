"""walk_client.py's command line without a simulator: --help, a bad option (exit 2, one
line naming it), no ROS master (exit 1, one line, no traceback); beside a stand-in
AtlasSimInterface on a private master (fake_asi_simulator.py): from the start's hold (User) it
sends STAND first and says so, gives up in one line when the states stop, and Ctrl-C says
how many steps were taken (exit 130)."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

pytest.importorskip('atlas_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from tutorial_atlas_control.processes import RosMaster, stop_tree, wait_until

SCRIPT = Path(__file__).resolve().parents[2] / 'scripts' / 'walk_client.py'


def run(*args: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True,
                          timeout=60, check=False, env=env)


def test_help_says_what_it_does() -> None:
    done = run('--help')
    assert done.returncode == 0
    assert 'next_step_index_needed' in done.stdout and '--once' in done.stdout


@pytest.mark.parametrize(('args', 'message'), [
    (('--steps', '0'), "argument --steps: '0' must be at least 1"),
    (('--stride', 'nan'), "argument --stride: 'nan' must be a positive number"),
    (('--circle', '0.1'), 'radius 0.1 m: the inner foot would cross the centre')])
def test_a_bad_option_exits_2_naming_it(args: tuple[str, ...], message: str) -> None:
    done = run(*args)
    assert done.returncode == 2
    assert done.stderr.splitlines()[-1] == f'walk_client.py: error: {message}'


def test_without_a_master_it_exits_1_with_one_line() -> None:
    with socket.socket() as probe:  # a port nobody listens on
        probe.bind(('127.0.0.1', 0))
        port = probe.getsockname()[1]
    env = {**os.environ, 'ROS_MASTER_URI': f'http://127.0.0.1:{port}'}
    done = run(env=env)
    assert done.returncode == 1
    assert done.stderr.strip() == (f'walk_client.py: error: no ROS master at '
                                   f'http://127.0.0.1:{port}: start the simulator first')


FAKE_ASI = Path(__file__).resolve().parent / 'fake_asi_simulator.py'


@pytest.fixture
def master(tmp_path: Path) -> Iterator[RosMaster]:
    with RosMaster(tmp_path / 'roscore.log', ros_log_dir=tmp_path / 'ros_log') as core:
        core.wait_online(60.0)
        yield core


def fake_asi(master: RosMaster, states_for_s: float) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, str(FAKE_ASI), '--states-for', str(states_for_s),
                             '--run-for', '120'], env=master.env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)


def test_from_the_start_hold_it_stands_first_and_gives_up_when_states_stop(
        master: RosMaster) -> None:
    simulator = fake_asi(master, states_for_s=8.0)
    try:
        client = subprocess.Popen([sys.executable, str(SCRIPT), '--steps', '4'], env=master.env,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        out, err = client.communicate(timeout=60)
        assert client.returncode == 1, err
        assert ("walk_client.py: the robot is in User (the tutorial's hold): sending STAND "
                'first') in out
        assert err.strip() == ('walk_client.py: error: no /atlas/atlas_sim_interface_state '
                               'for 2 s: the simulator stopped or is paused (0 of 4 steps '
                               'taken)')
        stop_tree(simulator)
        received = json.loads(simulator.communicate(timeout=30)[0].splitlines()[-1])
        assert received['received'] == [0, 4]  # STAND, then its WALK windows
    finally:
        stop_tree(simulator)


def test_ctrl_c_says_how_many_steps_were_taken(master: RosMaster) -> None:
    simulator = fake_asi(master, states_for_s=120.0)
    try:
        client = subprocess.Popen([sys.executable, str(SCRIPT), '--steps', '4'], env=master.env,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                  start_new_session=True)
        wait_until(lambda: any(command == 4 for command in _walks_seen(master)), 60.0,
                   'walk_client.py to stream its WALK')
        client.send_signal(signal.SIGINT)
        _, err = client.communicate(timeout=30)
        assert client.returncode == 130
        assert err.strip() == 'walk_client.py: interrupted after 0 of 4 steps'
    finally:
        stop_tree(simulator)


def _walks_seen(master: RosMaster) -> list[int]:
    """The behaviours on /atlas/atlas_sim_interface_command now (rostopic echo, one)."""
    done = subprocess.run(['rostopic', 'echo', '-n', '1', '/atlas/atlas_sim_interface_command/'
                           'behavior'], env=master.env, capture_output=True, text=True,
                          timeout=30, check=False)
    return [int(line) for line in done.stdout.split() if line.strip().isdigit()]
