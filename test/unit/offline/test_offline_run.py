"""run_offline.py: a trajectory played without ROS into the simulator, written as a live run's bag.

Short runs (a 0.1 s waypoint after 1.1 s, 0.2 s of settling) keep each test to a second.
"""

from __future__ import annotations

import importlib.util
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.cli.run_offline import main
from tutorial_atlas_control.joints import ATLAS_PREFIX, JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.offline.player import run_offline
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.trajectories.trajectory import TrajectoryError

REPO = Path(__file__).resolve().parents[3]
SCRIPT = REPO / 'scripts' / 'run_offline.py'
GAINS = REPO / 'config' / 'atlas_controller.yaml'
ELX = JOINT_NAMES.index('l_arm_elx')
#: What a live run records (test/integration/test_recorded_run.py), with the MD5 sums.
RECORDED = {
    '/clock': ('rosgraph_msgs/Clock', 'a9c97c1d230cfc112e270351a944ee47'),
    '/atlas/joint_states': ('sensor_msgs/JointState', '3066dcd76a6cfaef579bd0f34173e9fd'),
    '/ground_truth_odom': ('nav_msgs/Odometry', 'cd5e73d190d741a2f92e81eda573aca7'),
    '/atlas/imu': ('sensor_msgs/Imu', '6a62c6daae103f4ff57a132d6f95cec2'),
    '/atlas/l_foot_contact': ('geometry_msgs/WrenchStamped', 'd78d3cb249ce23087ade7e7d0c40cfa7'),
    '/atlas/r_foot_contact': ('geometry_msgs/WrenchStamped', 'd78d3cb249ce23087ade7e7d0c40cfa7'),
    '/atlas/joint_commands': ('osrf_msgs/JointCommands', 'f298c98f3e9c7aae9376ac19f73bfba3'),
    '/atlas/control_mode': ('std_msgs/String', '992ce8a1687cec8c8bd883ec73ca41d1'),
    '/atlas/sim_config': ('std_msgs/String', '992ce8a1687cec8c8bd883ec73ca41d1'),
    '/rosout': ('rosgraph_msgs/Log', 'acffd30cd6b6de30f120938c17c593fb'),
    '/tf': ('tf2_msgs/TFMessage', '94810edda583a504dfda3829e70d7eec'),
}
START_AFTER_S = 1.1
SETTLE_S = 0.2
#: The short trajectory: l_arm_elx to 0.3 rad in 0.1 s (5 commands at 50 Hz).
TARGET = np.zeros(NUM_JOINTS)
TARGET[ELX] = 0.3


@pytest.fixture()
def trajectory_file(tmp_path: Path) -> Path:
    path = tmp_path / 'short.yaml'
    path.write_text('elbow:\n  - [0.1, "' + ' '.join(f'{v:g}' for v in TARGET) + '"]\n'
                    'other:\n  - [1.0, "' + ' '.join(['0'] * NUM_JOINTS) + '"]\n')
    return path


def short_run(trajectory_file: Path, bag: Path):
    return run_offline(str(trajectory_file), 'elbow', bag, settle_s=SETTLE_S,
                       start_after_s=START_AFTER_S, gains_file=GAINS)


def raw_messages(bag: Path, topic: str) -> list[tuple[int, bytes]]:
    import rosbag
    with rosbag.Bag(str(bag)) as opened:
        return [(t.to_nsec(), raw[1]) for _, raw, t in opened.read_messages(topics=[topic],
                                                                             raw=True)]


def test_two_runs_are_identical(trajectory_file: Path, tmp_path: Path) -> None:
    first, second = tmp_path / 'first.bag', tmp_path / 'second.bag'
    short_run(trajectory_file, first)
    short_run(trajectory_file, second)
    states = raw_messages(first, '/atlas/joint_states')
    assert len(states) == round((START_AFTER_S + 0.1 + SETTLE_S) * 1000) + 1
    assert states == raw_messages(second, '/atlas/joint_states')
    assert first.read_bytes() == second.read_bytes()


def test_bag_opens_in_debian_rosbag_as_a_live_run(trajectory_file: Path, tmp_path: Path) -> None:
    import rosbag
    bag = tmp_path / 'run.bag'
    run = short_run(trajectory_file, bag)
    with rosbag.Bag(str(bag)) as opened:
        info = opened.get_type_and_topic_info()
        assert {topic: (value.msg_type, ) for topic, value in info.topics.items()} == {
            topic: (msgtype, ) for topic, (msgtype, _md5) in RECORDED.items()}
        assert {msgtype: md5 for msgtype, md5 in info.msg_types.items()} == dict(RECORDED.values())
        commands = [(msg, t)
                    for _, msg, t in opened.read_messages(topics=['/atlas/joint_commands'])]
        modes = [(msg.data, t.to_sec()) for _, msg, t in
                 opened.read_messages(topics=['/atlas/control_mode'])]
        logs = [msg.msg for _, msg, _ in opened.read_messages(topics=['/rosout'])]
        config = [json.loads(msg.data) for _, msg, _ in
                  opened.read_messages(topics=['/atlas/sim_config'])]
        states = [msg for _, msg, _ in opened.read_messages(topics=['/atlas/joint_states'])]
        compression = opened.get_compression_info()
    # Chunks compressed as a live run's (atlas.launch's lz4 default): about half the bytes.
    assert compression.compression == 'lz4'
    assert compression.compressed < 0.7 * compression.uncompressed
    assert run.commands == 5 == len(commands)
    # traj_yaml's schedule on the sim clock: every 20 ms from the switch to User mode.
    stamps_ns = [msg.header.stamp.to_nsec() for msg, _ in commands]
    assert stamps_ns == [1_100_000_000 + 20_000_000 * k for k in range(5)]
    assert [t.to_nsec() for _, t in commands] == stamps_ns
    assert modes == [('User', START_AFTER_S)]
    assert logs[0] == ('trajectory: ' + json.dumps({'file': str(trajectory_file), 'name': 'elbow'}))
    assert config[0]['time_to_unpin'] == 1.0 and config[0]['timestep'] == 0.001
    last = commands[-1][0]
    assert list(last.name) == [ATLAS_PREFIX + name for name in JOINT_NAMES]
    assert np.array_equal(last.position, TARGET)
    gains = load_gains_yaml(GAINS)
    assert np.array_equal(last.kp_position, gains.p) and np.array_equal(last.i_effort_max,
                                                                          gains.i_clamp)
    # The first command starts from the measured pose (the state at the switch).
    at_switch = next(msg for msg in states if msg.header.stamp.to_nsec() == 1_100_000_000)
    assert np.array_equal(commands[0][0].position, at_switch.position)
    assert [msg.header.seq for msg in states[:3]] == [1, 2, 3]


@pytest.mark.skipif(importlib.util.find_spec('osrf_msgs') is None,
                    reason='needs the catkin workspace: source ./env.sh')
def test_commands_are_the_bytes_traj_yaml_publishes(trajectory_file: Path, tmp_path: Path) -> None:
    import genpy
    from osrf_msgs.msg import JointCommands
    from rospy.msg import serialize_message

    from tutorial_atlas_control.trajectories.traj_yaml_node import build_command

    bag = tmp_path / 'run.bag'
    short_run(trajectory_file, bag)
    gains = load_gains_yaml(GAINS)
    for seq, (stamp_ns, raw) in enumerate(raw_messages(bag, '/atlas/joint_commands'), start=1):
        positions = np.frombuffer(raw, dtype='<f8', count=NUM_JOINTS,
                                  offset=len(raw) - 9 * (4 + 8 * NUM_JOINTS) + 4)
        buffer = io.BytesIO()
        serialize_message(buffer, seq, build_command(JointCommands, positions, gains,
                                                     genpy.Time(*divmod(stamp_ns, 10**9))))
        assert buffer.getvalue()[4:] == raw


def test_analyze_and_replay_read_the_bag(trajectory_file: Path, tmp_path: Path) -> None:
    bag = tmp_path / 'run.bag'
    short_run(trajectory_file, bag)
    analyzed = subprocess.run([sys.executable, str(REPO / 'scripts' / 'analyze_bag.py'), str(bag)],
                              capture_output=True, text=True, check=False)
    assert analyzed.returncode == 0, analyzed.stderr
    assert "Trajectory: 'elbow' of " in analyzed.stdout
    assert 'Commands: 5 on /atlas/joint_commands' in analyzed.stdout
    replayed = subprocess.run([sys.executable, str(REPO / 'scripts' / 'replay_bag.py'), str(bag),
                               '--json'], capture_output=True, text=True, check=False)
    assert replayed.returncode == 0, replayed.stdout + replayed.stderr
    assert json.loads(replayed.stdout)['reproduced'] is True


def test_summary_without_bag(trajectory_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main([str(trajectory_file), 'elbow', '--start-after', '1.1', '--settle', '0.2']) == 0
    out = capsys.readouterr().out
    assert '=== summary ===' in out
    assert 'the robot did not fall' in out
    assert 'that moved): l_arm_elx ' in out
    assert 'bag:' not in out
    assert main([str(trajectory_file), 'elbow', '--start-after', '1.1', '--settle', '0.2',
                 '--table']) == 0
    assert '  l_arm_elx  RMS ' in capsys.readouterr().out


def run_script(args: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, str(SCRIPT), *args], cwd=cwd, capture_output=True,
                          text=True, timeout=120, check=False)


@pytest.mark.parametrize(('args', 'message'), [
    (['missing.yaml', 'elbow'],
     'missing.yaml: cannot read trajectory file: No such file or directory'),
    (['short.yaml', 'nope'], 'unable to find trajectory nope in short.yaml'),
    (['bad.yaml', 'elbow'], "bad.yaml: trajectory 'elbow', waypoint 0: duration must be positive"),
    (['short.yaml', 'elbow', '--gains', 'missing_gains.yaml'], 'Could not read gains from'),
    (['short.yaml', 'elbow', '--bag', 'no/such/dir/out.bag'],
     'directory no/such/dir does not exist'),
])
def test_errors_are_one_line_and_write_nothing(trajectory_file: Path, args: list[str],
                                                message: str) -> None:
    directory = trajectory_file.parent
    (directory / 'bad.yaml').write_text('elbow:\n  - [0, "' + ' '.join(['0'] * NUM_JOINTS) + '"]\n')
    (directory / 'out.bag').write_bytes(b'previous run')
    before = sorted(os.listdir(directory))
    result = run_script([*args, '--bag', 'out.bag'] if '--bag' not in args else args, directory)
    assert result.returncode == 1
    assert result.stdout == ''
    assert result.stderr.count('\n') == 1 and message in result.stderr, result.stderr
    assert sorted(os.listdir(directory)) == before
    assert (directory / 'out.bag').read_bytes() == b'previous run'


def test_load_errors_raise_before_any_file(trajectory_file: Path, tmp_path: Path) -> None:
    with pytest.raises(TrajectoryError, match='unable to find trajectory x in'):
        run_offline(str(trajectory_file), 'x', tmp_path / 'x.bag')
    assert not list(tmp_path.glob('*.bag')) and not list(tmp_path.glob('.*partial'))
