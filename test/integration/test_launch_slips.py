"""Slips with atlas.launch, each ending in one line and a closed, readable bag.

A second atlas.launch on the master the first one started: the second's simulator refuses
in one line before registering, the second launch ends without a bag, and the first one
(master, simulator, recorder) goes on and records its whole run. A
$DISPLAY no X server answers (gui's default is true whenever $DISPLAY is set): one line,
and the simulator runs headless, recording. Real launches, about a minute each.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from support.bag_checks import missing_steps
from support.launch import (
    EXIT_TIMEOUT_S,
    RECORDER,
    SIM,
    STARTUP_TIMEOUT_S,
    TestLaunch,
    wait_sim_time,
)
from tutorial_atlas_control import processes
from tutorial_atlas_control.bags.reader import read_bag


def test_a_second_launch_is_refused_in_one_line_and_the_first_goes_on(
        tmp_path: Path) -> None:
    """As in the tutorial's two terminals: the first `roslaunch` starts the master, the
    second finds it running."""
    with TestLaunch(tmp_path / 'first') as first:
        first.wait_ready()
        first.wait_sim_s(2.0)
        sim_pid, recorder_pid = first.pid_of('atlas_sim_node'), first.pid_of('atlas_recorder')
        with TestLaunch(tmp_path / 'second', master=first) as second:
            second.wait_exit(EXIT_TIMEOUT_S + STARTUP_TIMEOUT_S)
            refused = second.output()
        master_uri = first.uri.rstrip('/')
        port = first.port + 1
        line = (f'atlas_sim: not started: /atlas_sim already runs on the ROS master '
                f'{master_uri} (an atlas.launch is running there); that one goes on, this '
                'launch stops. Stop the first (Ctrl-C in its terminal) before launching '
                f'again, or give this one its own master: roslaunch -p {port} '
                f'tutorial_atlas_control atlas.launch (and ROS_MASTER_URI=http://localhost:'
                f'{port} in the terminals that use it)')
        assert refused.count(line) == 1, refused
        assert 'Traceback' not in refused and 'took over' not in refused, refused
        assert not list((tmp_path / 'second' / 'bags').glob('*.bag*')), 'the second recorded'
        first.wait_sim_s(2.0)  # the first's master, simulator and recorder go on
        assert first.pid_of('atlas_sim_node') == sim_pid
        assert first.pid_of('atlas_recorder') == recorder_pid
        assert {SIM, RECORDER} <= set(first.subscribers('/atlas/joint_commands'))
        first.interrupt(EXIT_TIMEOUT_S)
        status = first.process.wait(timeout=EXIT_TIMEOUT_S)
        output = first.output()
    assert status == 0, output
    assert 'took over' not in output and 'has died' not in output, output
    states = read_bag(first.bag()).joint_states
    assert states is not None and len(states.t_s) > 3000, 'the bag holds the whole run'
    assert missing_steps(states) == 0


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
    assert falls[0].split(']: ', 1)[1].startswith(
        'the robot fell: pelvis below 0.5 m at sim time '), falls


def test_a_mistyped_launch_argument_gets_one_warning(tmp_path: Path) -> None:
    """roslaunch ignores recrod:=false; the simulator reads roslaunch's command line."""
    with TestLaunch(tmp_path, 'recrod:=false') as launch:
        launch.wait_ready()  # record's default, true, is what runs
        launch.interrupt(EXIT_TIMEOUT_S)
        output = launch.output()
    warnings = [line for line in output.splitlines() if 'roslaunch ignored' in line]
    assert len(warnings) == 1, output
    assert ('roslaunch ignored the argument recrod:=false: atlas.launch has no argument '
            'recrod; did you mean record:=false? (its arguments: ') in warnings[0]
