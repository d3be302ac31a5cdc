"""Tests of analyze_bag.py: output formats, files written, and error paths."""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from support.synthetic_bags import (
    clock,
    control_mode,
    joint_commands,
    joint_state,
    odometry,
    tracking_records,
    unindexed_copy,
    write_bag,
    write_run_bag,
)
from tutorial_atlas_control.cli.analyze_bag import main
from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS

SCRIPT = Path(__file__).resolve().parents[3] / 'scripts' / 'analyze_bag.py'


@pytest.fixture(scope='module')
def run_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """3 s run: arm swing from 1 s (User mode), the pelvis falls from 1.5 s."""
    return write_run_bag(tmp_path_factory.mktemp('bags') / 'run.bag', 3.0, with_imu=False,
                         fall_time_s=1.5)


def run_script(*args: str) -> subprocess.CompletedProcess[str]:
    """Run scripts/analyze_bag.py as a plain script: no PYTHONPATH, from another folder."""
    env = {key: value for key, value in os.environ.items() if key != 'PYTHONPATH'}
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True,
                          env=env, cwd='/', check=False, timeout=120)


def test_summary(run_bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main([str(run_bag)]) == 0
    out = capsys.readouterr().out
    assert 'Duration: 2.999 s' in out
    assert '/atlas/joint_states' in out and 'sensor_msgs/JointState' in out and '1000.00 Hz' in out
    assert '0.000 s  Stand' in out and '1.000 s  User' in out
    assert 'FELL at sim time 2.090 s, ' in out and '2.090 s from bag start' in out
    assert 'l_arm_shx' in out and 'r_arm_shx' in out
    assert 'Commands: 150 on /atlas/joint_commands at 50.0 Hz' in out
    assert 'no joint reached its effort limit' in out


def test_json(run_bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main([str(run_bag), '--json']) == 0
    result = json.loads(capsys.readouterr().out)
    for key in ('duration', 'fell', 'fall_time', 'topics', 'joints', 'mode_timeline',
                'command_rate', 'command_age', 'effort_saturation'):
        assert key in result
    assert result['fell'] is True
    assert result['fall_time'] == pytest.approx(2.09, abs=1e-6)
    assert result['topics']['/ground_truth_odom'] == {'type': 'nav_msgs/Odometry', 'count': 300,
                                                     'rate': pytest.approx(100.0)}
    assert set(result['joints']) == {'l_arm_shx', 'r_arm_shx'}
    assert set(result['joints']['l_arm_shx']) >= {'rms_error', 'max_error'}
    assert result['mode_timeline'] == [{'time': 0.0, 'mode': 'Stand'},
                                       {'time': 1.0, 'mode': 'User'}]
    assert result['command_rate'] == pytest.approx(50.0)
    assert result['command_age']['max'] < 0.02
    assert result['effort_saturation'] == {}


def test_json_without_joint_states_marks_metrics_unavailable(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = write_bag(tmp_path / 'no_states.bag', [control_mode(0.0, 'Stand'), odometry(0.5, 0.9)])
    assert main([str(bag), '--json']) == 0
    result = json.loads(capsys.readouterr().out)
    assert result['fell'] is False
    assert result['joints'] == {} and result['effort_saturation'] is None
    assert result['command_age'] is None and result['command_rate'] is None
    assert 'joints' in result['unavailable']


def test_summary_without_joint_states(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bag = write_bag(tmp_path / 'no_states.bag', [clock(0.0), clock(1.0)])
    assert main([str(bag)]) == 0
    out = capsys.readouterr().out
    assert 'Tracking: unavailable (no /atlas/joint_states in the bag)' in out
    assert 'Fall:     unknown' in out


def test_csv(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    elx = JOINT_NAMES.index('l_arm_elx')
    records = [clock(0.0), odometry(0.0, 0.9, x_m=0.25), odometry(0.01, 0.8)]
    records += [joint_commands(0.0, [0.5], names=['atlas::l_arm_elx'])]
    for step in range(3):
        position, effort = np.zeros(NUM_JOINTS), np.zeros(NUM_JOINTS)
        position[elx], effort[elx] = 0.1 * step, -2.0
        records.append(joint_state(0.005 * step, position, np.full(NUM_JOINTS, 0.5), effort))
    bag = write_bag(tmp_path / 'run.bag', records)
    out_dir = tmp_path / 'csv' / 'nested'
    assert main([str(bag), '--csv', str(out_dir)]) == 0
    assert sorted(path.name for path in out_dir.iterdir()) == [
        'joint_commands.csv', 'joint_states.csv', 'pelvis_pose.csv']

    with (out_dir / 'joint_states.csv').open() as stream:
        rows = list(csv.DictReader(stream))
    assert len(rows) == 3
    assert list(rows[0])[:2] == ['t', 'back_lbz_position']
    assert len(rows[0]) == 1 + 3 * NUM_JOINTS
    assert float(rows[2]['t']) == pytest.approx(0.010)
    assert float(rows[2]['l_arm_elx_position']) == pytest.approx(0.2)
    assert float(rows[2]['l_arm_elx_velocity']) == 0.5
    assert float(rows[2]['l_arm_elx_effort']) == -2.0

    with (out_dir / 'joint_commands.csv').open() as stream:
        rows = list(csv.DictReader(stream))
    assert len(rows) == 1
    assert float(rows[0]['l_arm_elx_position']) == 0.5
    assert rows[0]['neck_ay_position'] == 'nan'  # not in that message

    with (out_dir / 'pelvis_pose.csv').open() as stream:
        rows = list(csv.DictReader(stream))
    assert list(rows[0]) == ['t', 'x', 'y', 'z', 'qx', 'qy', 'qz', 'qw', 'vx', 'vy', 'vz', 'wx',
                             'wy', 'wz']
    assert [float(rows[0][key]) for key in ('t', 'x', 'z', 'qw')] == [0.0, 0.25, 0.9, 1.0]
    assert float(rows[1]['z']) == 0.8


def test_plot(run_bag: Path, tmp_path: Path) -> None:
    image = tmp_path / 'run.png'
    assert main([str(run_bag), '--plot', str(image)]) == 0
    assert image.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    assert image.stat().st_size > 10_000


def test_plot_of_a_bag_with_nothing_to_plot(tmp_path: Path) -> None:
    bag = write_bag(tmp_path / 'run.bag', [clock(0.0)])
    image = tmp_path / 'empty.png'
    assert main([str(bag), '--plot', str(image)]) == 0
    assert image.read_bytes()[:4] == b'\x89PNG'


def assert_one_error_line(result_err: str, pattern: str) -> None:
    lines = result_err.strip().splitlines()
    assert len(lines) == 1, result_err
    assert lines[0].startswith('analyze_bag.py: error: ')
    assert pattern in lines[0]
    assert 'Traceback' not in result_err


def test_missing_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main([str(tmp_path / 'nope.bag')]) == 1
    assert_one_error_line(capsys.readouterr().err, 'no such file')


def test_not_a_bag(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / 'traj.yaml'
    path.write_text('trajectory: []\n')
    assert main([str(path)]) == 1
    assert_one_error_line(capsys.readouterr().err, 'is not a ROS 1 bag')


def test_unwritable_plot(run_bag: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main([str(run_bag), '--plot', str(tmp_path / 'missing_dir' / 'x.png')]) == 1
    assert_one_error_line(capsys.readouterr().err, 'Could not write the plot')


def test_script_reports_unindexed_active_bag(tmp_path: Path) -> None:
    good = write_bag(tmp_path / 'good.bag', tracking_records('bare'))
    active = unindexed_copy(good, tmp_path / 'run.bag.active')
    result = run_script(str(active))
    assert result.returncode == 1
    assert_one_error_line(result.stderr, f'rosbag reindex {active}')
    assert result.stdout == ''


def test_script_runs_from_a_clone_and_prints_json(run_bag: Path) -> None:
    result = run_script(str(run_bag), '--json')
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)['fell'] is True


def test_script_is_thin_and_executable() -> None:
    assert os.access(SCRIPT, os.X_OK)
    assert SCRIPT.read_text().startswith('#!/usr/bin/env python3\n')


def test_help_documents_options_and_keys() -> None:
    result = run_script('--help')
    assert result.returncode == 0
    for text in ('--json', '--plot', '--csv', 'fall_time', 'effort_saturation', 'command_age',
                 'rosbag reindex', 'zero-order hold'):
        assert text in result.stdout
