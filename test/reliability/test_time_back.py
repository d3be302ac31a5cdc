"""Sim time going back under traj_yaml.py: /gazebo/reset_simulation mid-trajectory.

traj_yaml.py stops with one line and exit status 1 (it does not restart: the reset put
the robot back at its initial pose, and running it again plays the trajectory from the
start); the bag is analyzed as two tries, split at the reset, each readable.
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from support.launch import EXIT_TIMEOUT_S, TestLaunch
from tutorial_atlas_control.bags.analysis import analyze_bag
from tutorial_atlas_control.bags.tries import RESET_SIMULATION, RUN_START

REPO = Path(__file__).resolve().parents[2]
TRAJECTORIES = REPO / 'trajectories' / 'Traj_data2.yaml'


def test_reset_simulation_under_traj_yaml_stops_it_with_one_line(
        atlas_launch: TestLaunch) -> None:
    atlas_launch.wait_ready()
    atlas_launch.set_mode('User')
    traj = subprocess.Popen(
        ['rosrun', 'tutorial_atlas_control', 'traj_yaml.py', str(TRAJECTORIES), 'touchdown'],
        env=atlas_launch.env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        lines = []
        for line in traj.stdout:
            lines.append(line)
            if '(2 of 3)' in line:
                break
        else:
            pytest.fail(f'traj_yaml.py ended before its second waypoint: {"".join(lines)}')
        reset_at_s = atlas_launch.sim_time_s()
        result = atlas_launch.run('rosservice', 'call', '/gazebo/reset_simulation')
        assert result.returncode == 0, result.stderr
        rest, _ = traj.communicate(timeout=EXIT_TIMEOUT_S)
    finally:
        traj.kill()
    assert traj.returncode == 1, rest
    went_back = [line for line in rest.splitlines() if 'sim time went back' in line]
    assert len(went_back) == 1, rest
    assert ('(the simulation was reset: /gazebo/reset_simulation?); trajectory aborted, run '
            'traj_yaml.py again to play it from the start') in went_back[0]
    assert 'Traceback' not in rest and 'done' not in rest
    atlas_launch.wait_sim_until(2.0)  # the simulation goes on from 0
    atlas_launch.interrupt()

    analysis = analyze_bag(atlas_launch.bag())
    tries = [each.to_dict() for each in analysis.tries]
    summary = '\n'.join(str(each) for each in tries)
    assert [each['began_with'] for each in tries] == [RUN_START, RESET_SIMULATION], summary
    assert [[p['name'] for p in each['trajectories']] for each in tries] == [
        ['touchdown'], []], summary
    assert tries[1]['sim_start'] == pytest.approx(0.0, abs=0.01), summary
    assert tries[1]['command_count'] <= 1, 'nothing sent after the reset (one in flight)'
    print(f'figures: reset_simulation at sim time ~{reset_at_s:.2f} s: traj_yaml.py exit 1, '
          f'one line; bag split into 2 tries ({tries[0]["command_count"]} commands, then '
          f'{tries[1]["command_count"]})')
