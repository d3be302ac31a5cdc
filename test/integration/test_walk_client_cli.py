"""walk_client.py's command line without a simulator: --help, a bad option (exit 2, one
line naming it), no ROS master (exit 1, one line, no traceback)."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip('atlas_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

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
