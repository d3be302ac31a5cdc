"""Every script follows tutorial_atlas_control.cli.convention, run from a clone, anywhere."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPTS = Path(__file__).resolve().parents[3] / 'scripts'
PYTHON_SCRIPTS = ('analyze_bag.py', 'replay_bag.py', 'run_demo.py', 'run_offline.py',
                  'traj_yaml.py', 'plot_topics.py', 'sweep.py', 'search.py', 'vrc_walker.py',
                  'course_sweep.py')


def run(script: str, *args: str) -> subprocess.CompletedProcess[str]:
    """The script as a user runs it: by path, without rosrun, from an unrelated directory."""
    command = [str(SCRIPTS / script), *args]
    if script.endswith('.py'):
        command.insert(0, sys.executable)
    return subprocess.run(command, capture_output=True, text=True, cwd='/', env=dict(os.environ),
                          check=False, timeout=120)


@pytest.mark.parametrize('script', [*PYTHON_SCRIPTS, 'record_run.sh'])
def test_help_works_from_anywhere(script: str) -> None:
    result = run(script, '--help')
    assert result.returncode == 0, result.stderr
    assert 'usage' in result.stdout.lower()


@pytest.mark.parametrize(('script', 'args', 'message'), [
    ('analyze_bag.py', ['run.bag', '--latest'], 'give BAG or --latest, not both'),
    ('replay_bag.py', ['run.bag', '--tolerance', '-1'], "argument --tolerance: '-1' is not"),
    ('run_demo.py', ['--video-size', 'big'], "argument --video-size: 'big' is not WIDTHxHEIGHT"),
    ('run_offline.py', ['Traj_data2.yaml', 'touchdown', '--settle', '-1'],
     "argument --settle: '-1' must be a finite number of seconds >= 0"),
    ('plot_topics.py', ['/a/b', '--window', '0'],
     "argument --window: '0' must be a finite number of seconds > 0"),
    ('sweep.py', ['Traj.yaml', 'bend', '--repeat', '0'], "argument --repeat: '0' must be at "
     'least 1'),
    ('sweep.py', ['Traj.yaml', 'bend', '--workers', '0'], "argument --workers: '0' must be at "
     'least 1'),
    ('search.py', ['Traj.yaml', 'bend', '--objective', 'stay_up', '--log', 'l', '--yaml', 'y',
                   '--latency-draws', '-1'], "argument --latency-draws: '-1' must be at least 0"),
    ('search.py', ['Traj.yaml', 'bend', '--objective', 'stay_up', '--log', 'l', '--yaml', 'y',
                   '--popsize', '0'], "argument --popsize: '0' must be at least 1"),
    ('vrc_walker.py', ['--to', 'gate_5'], "argument --to: invalid choice: 'gate_5'"),
    ('vrc_walker.py', ['--stride', '0'], "argument --stride: '0' must be a finite number > 0"),
    ('course_sweep.py', ['--variants', 'finals'], "argument --variants: invalid choice: "
     "'finals'"),
    ('course_sweep.py', ['--seeds', 'x'], "argument --seeds: seed 'x' is not an integer"),
    ('record_run.sh', [], 'expected BAG_DIR [atlas_recorder|rosbag [lz4|bz2|none]], got 0 '
     'argument(s)'),
    ('record_run.sh', ['/tmp', 'rosbag2'], "unknown recorder 'rosbag2'"),
    ('record_run.sh', ['/tmp', 'rosbag', 'zstd'],
     "unknown compression 'zstd' (expected lz4, bz2 or none)"),
])
def test_bad_command_line_exits_2(script: str, args: list[str], message: str) -> None:
    result = run(script, *args)
    assert result.returncode == 2, result
    last = result.stderr.strip().splitlines()[-1]
    assert last.startswith(f'{script}: error: ') and message in last, result.stderr
    assert 'Traceback' not in result.stderr


@pytest.mark.parametrize(('script', 'args', 'message'), [
    ('analyze_bag.py', ['/nonexistent/run.bag'], 'no such file'),
    ('replay_bag.py', ['/nonexistent/run.bag'], 'no such file'),
    ('run_demo.py', ['--file', '/nonexistent/Traj.yaml'], '/nonexistent/Traj.yaml: cannot read'),
    ('run_offline.py', ['/nonexistent/Traj.yaml', 'touchdown'],
     '/nonexistent/Traj.yaml: cannot read'),
])
def test_refused_input_exits_1_with_one_line(script: str, args: list[str], message: str) -> None:
    result = run(script, *args)
    assert result.returncode == 1, result
    assert result.stderr.splitlines() == [result.stderr.strip()], 'one line'
    assert result.stderr.startswith(f'{script}: error: ') and message in result.stderr


def test_traj_yaml_keeps_the_tutorial_command_line() -> None:
    """The exception: DRCSim's usage text and exit status 1."""
    result = run('traj_yaml.py')
    assert result.returncode == 1
    assert result.stderr.startswith('usage: traj_yaml.py YAML_FILE TRAJECTORY_NAME')
