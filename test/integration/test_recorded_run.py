"""The main job end to end: `run_demo.py` runs the tutorial and leaves one closed, indexed bag.

Needs the catkin workspace (`source ./env.sh`); runs roslaunch on its own master port.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')

from rosbags.highlevel import AnyReader

from tutorial_atlas_control.trajectories.trajectory import load_trajectory, sample_count

REPO = Path(__file__).resolve().parents[2]
DRCSIM_MD5 = 'f298c98f3e9c7aae9376ac19f73bfba3'
#: DRCSim's 1 kHz topics whose numbers the bag holds already (README): never recorded.
DRCSIM_DUPLICATES = ('/atlas/atlas_state', '/atlas/force_torque_sensors',
                     '/atlas/debug/l_foot_contact', '/atlas/debug/r_foot_contact')
RECORDED_TYPES = {
    '/clock': 'rosgraph_msgs/msg/Clock',
    '/atlas/joint_states': 'sensor_msgs/msg/JointState',
    '/ground_truth_odom': 'nav_msgs/msg/Odometry',
    '/atlas/imu': 'sensor_msgs/msg/Imu',
    '/atlas/l_foot_contact': 'geometry_msgs/msg/WrenchStamped',
    '/atlas/r_foot_contact': 'geometry_msgs/msg/WrenchStamped',
    '/atlas/joint_commands': 'osrf_msgs/msg/JointCommands',
    '/atlas/control_mode': 'std_msgs/msg/String',
    '/atlas/sim_config': 'std_msgs/msg/String',
    '/rosout': 'rosgraph_msgs/msg/Log',
    '/atlas/controller_statistics': 'atlas_msgs/msg/ControllerStatistics',
    '/tf': 'tf2_msgs/msg/TFMessage',
}
CONTROLLER_STATISTICS_MD5 = '628a0c6643f9fd5708402f085735e478'
TRAJECTORIES = REPO / 'trajectories' / 'Traj_data2.yaml'
#: The tutorial's command period (s of sim time): 50 Hz.
COMMAND_PERIOD_S = 0.02
#: The simulator's step, the resolution of /clock and so of the commands' stamps (s).
CLOCK_STEP_S = 0.001
MAX_COMMANDS_MISSED = 1


def test_demo_exits_0_and_prints_summary_bag_and_plot(demo_run) -> None:
    result, bag_dir = demo_run.result, demo_run.bag_dir
    assert result.returncode == 0, result.stdout + result.stderr
    assert 'the robot fell: pelvis below 0.5 m at sim time ' in result.stdout
    bags = list(bag_dir.glob('atlas_*.bag'))
    assert len(bags) == 1
    assert f'bag:   {bags[0]}' in result.stdout
    plot = bags[0].with_suffix('.png')
    assert f'plot:  {plot}' in result.stdout
    assert plot.stat().st_size > 10_000
    video = bags[0].with_suffix('.mp4')
    assert f'video: {video}' in result.stdout
    assert video.stat().st_size > 10_000


def test_bag_is_closed_and_indexed(demo_run) -> None:
    bag_dir = demo_run.bag_dir
    assert not list(bag_dir.glob('*.active')), 'rosbag left an unclosed .bag.active'
    bag = next(bag_dir.glob('atlas_*.bag'))
    info = subprocess.run(['rosbag', 'info', '--yaml', '--key=indexed', str(bag)],
                          capture_output=True, text=True, check=True)
    assert info.stdout.strip() == 'True'


def test_bag_holds_the_run(demo_run) -> None:
    bag_dir = demo_run.bag_dir
    bag = next(bag_dir.glob('atlas_*.bag'))
    with AnyReader([bag]) as reader:
        connections = {c.topic: c for c in reader.connections}
        for topic, msgtype in RECORDED_TYPES.items():
            assert topic in connections, topic
            assert connections[topic].msgtype == msgtype, topic
        assert connections['/atlas/joint_commands'].digest == DRCSIM_MD5
        assert connections['/atlas/controller_statistics'].digest == CONTROLLER_STATISTICS_MD5
        # README: DRCSim's 1 kHz duplicates are published but not recorded.
        assert not set(connections) & set(DRCSIM_DUPLICATES), sorted(connections)

        commands = []
        for c, _t, raw in reader.messages(connections=[connections['/atlas/joint_commands']]):
            stamp = reader.deserialize(raw, c.msgtype).header.stamp
            commands.append(stamp.sec * 10**9 + stamp.nanosec)
        modes = [reader.deserialize(raw, c.msgtype).data for c, _t, raw in
                 reader.messages(connections=[connections['/atlas/control_mode']])]
        state_stamps = np.array([t for _c, t, _r in reader.messages(
            connections=[connections['/atlas/joint_states']])])

    # 50 Hz of sim time: each command is due 20 ms after the previous one's due time, and its
    # stamp is ROS time, the simulator's /clock in 1 ms steps: the median spacing is 20 ms to
    # one step. Every command of the trajectory is in the bag (the port waits for rospy's
    # hand-over, atlas_recorder loses none); one is allowed for a hand-over that timed out.
    # The rate in wall time is `make bench`'s (tutorial_command_rate_hz).
    waypoints = load_trajectory(TRAJECTORIES, 'step_and_fall')
    expected = sum(sample_count(w.duration_s) for w in waypoints)
    assert expected - MAX_COMMANDS_MISSED <= len(commands) <= expected
    period_s = float(np.median(np.diff(np.sort(commands)))) / 1e9
    assert abs(period_s - COMMAND_PERIOD_S) <= CLOCK_STEP_S + 1e-9, period_s
    assert 'User' in modes
    # Joint states every 1 ms of sim time (bag time is sim time under /use_sim_time).
    span_s = (state_stamps[-1] - state_stamps[0]) / 1e9
    assert len(state_stamps) / span_s == pytest.approx(1000.0, rel=0.02)


def test_the_simulator_logged_the_fall_once_as_the_pelvis_dropped(demo_run) -> None:
    """Headless, the fall line is the user's sign of a fall: one, at the odometry's fall."""
    from support.bag_checks import log_lines, messages

    info = 2  # rosgraph_msgs/Log INFO
    falls = [line for line in log_lines(demo_run.bag, min_level=info) if 'the robot fell' in line]
    assert len(falls) == 1, falls
    match = re.fullmatch(r'the robot fell: pelvis below 0\.5 m at sim time (\d+\.\d{3}) s, '
                         r"(\d+\.\d{3}) s after the try's first command", falls[0])
    assert match, falls[0]
    # One clock: the demo's summary gives the live line's figures, word for word.
    assert falls[0] in demo_run.result.stdout.splitlines(), demo_run.result.stdout
    odom = [(msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9, msg.pose.pose.position.z)
            for msg in messages(demo_run.bag, '/ground_truth_odom')]
    odom_fall_s = next(t_s for t_s, z_m in odom if z_m < 0.5)
    # The line comes at the end of the step that crossed 0.5 m, odometry every 10 ms: its first
    # reading below comes up to 10 ms later.
    assert odom_fall_s - 0.011 <= float(match[1]) <= odom_fall_s + 0.002
    assert 1.0 < float(match[2]) < 3.0  # step_and_fall: 1.8-2.0 s after its first command
