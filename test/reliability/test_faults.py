"""Faults injected into a running atlas.launch: each leaves a closed, readable, complete bag.

The simulator runs at real time here (the default), as a user's session does.
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from support.bag_checks import (
    ERROR,
    FATAL,
    all_finite,
    count,
    log_lines,
    missing_steps,
    sim_configs,
)
from support.launch import EXIT_TIMEOUT_S, TestLaunch
from tutorial_atlas_control.bags.reader import read_bag
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.processes import alive

REPO = Path(__file__).resolve().parents[2]
TRAJECTORIES = REPO / 'trajectories' / 'Traj_data2.yaml'
GAINS = REPO / 'config' / 'atlas_controller.yaml'
MODEL = REPO / 'sim' / 'atlas_v1.xml'
ARM_JOINTS = ('l_arm_shx', 'r_arm_shx', 'l_arm_elx', 'r_arm_elx')


def test_sigint_stops_every_process_and_closes_the_bag(atlas_launch: TestLaunch) -> None:
    """How fast they go is `make bench`'s `shutdown_s` (target 5 s)."""
    atlas_launch.wait_ready()
    atlas_launch.wait_sim_s(3.0)
    pids = atlas_launch.pids()
    gone_s = atlas_launch.interrupt(EXIT_TIMEOUT_S)
    print(f'figures: SIGINT to roslaunch: {len(pids)} processes gone in {gone_s:.2f} s')
    assert not alive(pids), f'processes left {gone_s:.0f} s after SIGINT: {alive(pids)}'
    assert 'the recorder (/recorder) stopped' not in atlas_launch.output(), \
        'a recorder stopped by Ctrl-C is not reported as a fault'
    bag = atlas_launch.bag()
    states = read_bag(bag).joint_states
    assert states is not None and len(states.t_s) > 2000, 'the bag holds the run'
    assert missing_steps(states) == 0
    assert count(bag, '/atlas/sim_config') == 1


def test_simulator_killed_with_sigkill_leaves_a_readable_bag(atlas_launch: TestLaunch) -> None:
    atlas_launch.wait_ready()
    atlas_launch.wait_sim_s(3.0)
    os.kill(atlas_launch.pid_of('atlas_sim_node.py'), signal.SIGKILL)
    # The simulator is a required node: roslaunch stops the recorder (SIGINT) and exits.
    atlas_launch.wait_exit()
    assert 'REQUIRED process [atlas_sim' in atlas_launch.output()
    bag = atlas_launch.bag()
    data = read_bag(bag)
    assert data.joint_states is not None and len(data.joint_states.t_s) > 2000
    assert missing_steps(data.joint_states) == 0
    assert all_finite(data.joint_states)
    print(f'figures: SIGKILL of the simulator: bag readable, '
          f'{len(data.joint_states.t_s)} joint states, none missing')


def test_killed_traj_yaml_leaves_the_robot_holding_its_last_command(
        atlas_launch: TestLaunch) -> None:
    atlas_launch.wait_ready()
    atlas_launch.set_mode('User')
    traj = subprocess.Popen(
        ['rosrun', 'tutorial_atlas_control', 'traj_yaml.py', str(TRAJECTORIES), 'touchdown'],
        env=atlas_launch.env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        for line in traj.stdout:  # killed part-way through the second waypoint
            if '(2 of 3)' in line:
                break
        else:
            pytest.fail(f'traj_yaml.py ended before its second waypoint (status {traj.wait()})')
        time.sleep(1.0)
        traj.kill()
        traj.wait()
    finally:
        traj.kill()
    atlas_launch.wait_sim_s(4.0)
    atlas_launch.interrupt()

    data = read_bag(atlas_launch.bag())
    states, commands, pelvis = data.joint_states, data.commands, data.pelvis
    last_command_s = float(commands.t_s[-1])
    assert states.t_s[-1] - last_command_s >= 3.0, 'the simulator kept running and recording'
    assert missing_steps(states) == 0
    assert all_finite(states)
    last_targets = commands.held[-1]
    final = states.position[-1]
    for joint in ARM_JOINTS:
        index = JOINT_NAMES.index(joint)
        column = states.names.index(joint)
        assert abs(final[column] - last_targets[index]) < 0.1, \
            f'{joint} holds the last command ({last_targets[index]:.3f} rad)'
    assert float(np.min(pelvis.position_m[:, 2])) > 0.7, 'the robot stays up'
    print(f'figures: traj_yaml.py killed at t={last_command_s:.2f} s; recording went on '
          f'{states.t_s[-1] - last_command_s:.2f} s, none missing; arms held within 0.1 rad')


def _gains_file(tmp_path: Path, joint: str, key: str, value: object) -> Path:
    tree = yaml.safe_load(GAINS.read_text())
    gains = tree['atlas_controller']['gains'][joint]
    if value is None:
        del gains[key]
    else:
        gains[key] = value
    path = tmp_path / 'bad_gains.yaml'
    path.write_text(yaml.safe_dump(tree))
    return path


@pytest.mark.parametrize(('edit', 'expected'), [
    (('l_arm_elx', 'p', None), 'parameter atlas_controller/gains/l_arm_elx/p is missing'),
    (('r_leg_kny', 'd', 'fast'), 'atlas_controller/gains/r_leg_kny/d'),
])
def test_bad_gains_stop_the_launch_naming_the_parameter(
        tmp_path: Path, edit: tuple, expected: str) -> None:
    with TestLaunch(tmp_path, f'gains_file:={_gains_file(tmp_path, *edit)}') as launch:
        launch.wait_exit()
        output = launch.output()
        assert expected in output, output
        assert 'FATAL' in output or 'atlas_sim: ' in output
        assert not list(launch.bag_dir.glob('*.active')), 'no half-written bag'


def test_non_numeric_launch_parameter_stops_the_launch(tmp_path: Path) -> None:
    with TestLaunch(tmp_path, 'time_to_unpin:=soon') as launch:
        launch.wait_exit()
        assert "parameter /atlas/time_to_unpin must be a number >= 0.0, got 'soon'" \
            in launch.output()
        assert not list(launch.bag_dir.glob('*.active')), 'no half-written bag'


def test_forced_divergence_is_reported_reset_and_never_published(tmp_path: Path) -> None:
    """A model variant whose gravity no step survives: every step diverges.

    It starts paused so that the recorder is connected before the first step.
    """
    model = tmp_path / 'diverging_atlas.xml'
    model.write_text(MODEL.read_text().replace('<option ', '<option gravity="0 0 -1e9" ', 1))
    with TestLaunch(tmp_path, f'model:={model}', 'paused:=true') as launch:
        launch.wait_ready()
        time.sleep(1.0)
        result = launch.run('rosservice', 'call', '/gazebo/unpause_physics')
        assert result.returncode == 0, result.stderr
        launch.wait_exit()
        assert 'REQUIRED process [atlas_sim' in launch.output()
        bag = launch.bag()
    errors = log_lines(bag, min_level=ERROR)
    diverged = [line for line in errors if 'physics diverged' in line]
    assert len(diverged) == 3, errors
    assert all('resetting the robot to its initial state' in line for line in diverged[:2])
    assert f'{model.name} is unstable; stopping the simulator' in diverged[2], 'names model:='
    assert log_lines(bag, min_level=FATAL) == diverged[2:]
    resets = [config.last_reset_time_s for config in sim_configs(bag)]
    assert len(resets) == 3, f'one /atlas/sim_config at start and one per reset: {resets}'
    states = read_bag(bag).joint_states
    assert states is not None and all_finite(states), 'no NaN/Inf was published'
    at_initial_pose = int(np.sum(np.abs(states.position).max(axis=1) < 1e-9))
    assert at_initial_pose >= 2, 'each reset publishes the initial pose'
    print(f'figures: forced divergence: {len(diverged)} reported, 2 resets, then stopped; '
          f'{len(states.t_s)} joint states, all finite')
