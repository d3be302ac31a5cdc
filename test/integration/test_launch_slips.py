"""Slips with atlas.launch, each ending in one line and a closed, readable bag.

A second atlas.launch on the same master: the first simulator says another one took over
and stops, its launch ends and its bag is closed and readable; the second runs on. A
$DISPLAY no X server answers (gui's default is true whenever $DISPLAY is set): one line,
and the simulator runs headless, recording. Real launches, about a minute each.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from support.bag_checks import missing_steps
from support.launch import EXIT_TIMEOUT_S, STARTUP_TIMEOUT_S, TestLaunch, wait_sim_time
from tutorial_atlas_control import processes
from tutorial_atlas_control.bags.reader import read_bag


def test_a_second_launch_replaces_the_first_which_exits_with_one_line(tmp_path: Path) -> None:
    with TestLaunch(tmp_path / 'first') as first:
        first.wait_ready()
        first.wait_sim_s(2.0)
        second_bags = tmp_path / 'second' / 'bags'
        second = processes.AtlasLaunch(
            tmp_path / 'second.log', {'gui': 'false', 'bag_dir': str(second_bags)},
            master=first, ros_log_dir=tmp_path / 'second' / 'ros_log')
        with second:
            status = first.wait_exit(EXIT_TIMEOUT_S + STARTUP_TIMEOUT_S)
            output = first.output()
            master_uri = first.env['ROS_MASTER_URI'].rstrip('/')
            line = ('atlas_sim: another atlas_sim took over: a second simulator registered as '
                    f'/atlas_sim on {master_uri}, so this one stops (its launch and recording '
                    'end); run one atlas.launch per master, or give the second its own '
                    '(roslaunch -p PORT)')
            assert status == 0, output
            assert output.count(line) == 1, output
            assert 'Traceback' not in output, output
            bag = first.bag()  # closed: no .active left
            info = subprocess.run(['rosbag', 'info', '--yaml', '--key=indexed', str(bag)],
                                  capture_output=True, text=True, check=True)
            assert info.stdout.strip() == 'True'
            states = read_bag(bag).joint_states
            assert states is not None and len(states.t_s) > 1000, 'the bag holds the run'
            assert missing_steps(states) == 0
            second.check_running()  # the second launch goes on


def test_a_display_without_x_server_runs_headless_with_one_line(tmp_path: Path) -> None:
    number = next(n for n in range(87, 200) if not Path(f'/tmp/.X11-unix/X{n}').exists())
    display = f':{number}'
    bag_dir = tmp_path / 'bags'
    launch = processes.AtlasLaunch(  # gui left to its default: true, as $DISPLAY is set
        tmp_path / 'launch.log', {'bag_dir': str(bag_dir)}, ros_log_dir=tmp_path / 'ros_log',
        base_env=dict(os.environ, DISPLAY=display))
    with launch:
        wait_sim_time(launch.env, 3.0)
        launch.check_running()
        launch.interrupt(EXIT_TIMEOUT_S)
        status = launch.process.wait(timeout=EXIT_TIMEOUT_S)
        output = launch.output()
    line = (f'cannot open the MuJoCo viewer: no X server answers at DISPLAY={display} (none '
            'running there, or a broken ssh -X forwarding); running headless, recording on '
            '(gui:=false starts without trying)')
    assert status == 0, output
    assert output.count(line) == 1, output
    assert 'GLFW' not in output and 'has died' not in output, output
    assert not list(bag_dir.glob('*.active')), 'the recorder left its bag unclosed'
    bag, = bag_dir.glob('atlas_*.bag')
    states = read_bag(bag).joint_states
    assert states is not None and len(states.t_s) > 1000, 'the bag holds the run'
    assert missing_steps(states) == 0


def test_forgotten_user_mode_a_reset_and_a_fall_each_say_so(tmp_path: Path) -> None:
    """The headless feedback, live: traj_yaml.py and the simulator warn about commands sent
    in Stand mode; a reset and a fall (ragdoll) each give the simulator's one line."""
    trajectory = tmp_path / 'short.yaml'
    trajectory.write_text('arms: [[0.2, "' + ' '.join(['0.0'] * 28) + '"]]\n')
    with TestLaunch(tmp_path) as launch:
        launch.wait_ready()
        launch.wait_sim_s(1.5)
        played = launch.run('rosrun', 'tutorial_atlas_control', 'traj_yaml.py', str(trajectory),
                            'arms', timeout_s=120.0)
        assert played.returncode == 0, played.stdout + played.stderr
        port_warning = ('the simulator is in Stand mode, which does not apply these commands: '
                        'the robot will not move; switch to User mode first: '
                        'rostopic pub /atlas/control_mode std_msgs/String -- "User"')
        assert (played.stdout + played.stderr).count(port_warning) == 1, played
        reset = launch.run('rosservice', 'call', '/gazebo/reset_world')
        assert reset.returncode == 0, reset.stderr
        launch.set_mode('ragdoll')
        launch.wait_sim_s(3.0)
        output = launch.output()
    sim_warning = ('/atlas/joint_commands arrive in Stand mode, which does not apply them; '
                   'switch to User mode: '
                   'rostopic pub /atlas/control_mode std_msgs/String -- "User"')
    assert output.count(sim_warning) == 1, output  # 11 commands in 0.2 s: one warning
    resets = [line for line in output.splitlines() if 'reset_world: robot back' in line]
    assert len(resets) == 1, output
    falls = [line for line in output.splitlines() if 'the robot fell' in line]
    assert len(falls) == 1, output
    assert falls[0].split(']: ', 1)[1].startswith('the robot fell: pelvis below 0.5 m at t='), falls
