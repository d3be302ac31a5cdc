"""scripts/traj_yaml.py's command line without a ROS master, and the node's pure helpers.

Every CLI error path runs the real script in a subprocess. ROS_MASTER_URI points at a
listening socket owned by the test, which then checks that nobody connected to it:
the file is validated before the script goes anywhere near ROS.
"""

from __future__ import annotations

import importlib.util
import math
import os
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from tutorial_atlas_control.joints import ATLAS_PREFIX, JOINT_INDEX, JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.sim.controller import Gains, GainsError
from tutorial_atlas_control.trajectories.schedule import TimeWentBackError
from tutorial_atlas_control.trajectories.traj_yaml_node import (
    JointStateCache,
    TrajYamlError,
    build_command,
    linger,
    mode_warning,
    positions_by_name,
    read_gains,
    run_trajectory,
    wait_for_joint_state,
    wait_for_log_readers,
    wait_for_ros_time,
    wait_for_subscribers,
    wait_until_handed_over,
)
from tutorial_atlas_control.trajectories.trajectory import Waypoint, sample_count

REPO = Path(__file__).resolve().parents[3]
SCRIPT = REPO / 'scripts' / 'traj_yaml.py'
TRAJECTORY_FILE = REPO / 'trajectories' / 'Traj_data2.yaml'
USAGE_LINES = ['usage: traj_yaml.py YAML_FILE TRAJECTORY_NAME',
               ' where TRAJECTORY is a dictionary defined in YAML_FILE']
#: Guard (s) against a run that hangs; that a run did not touch ROS is what
#: assert_untouched checks, not how fast it was.
HANG_GUARD_S = 120.0
#: Guard (s) for another thread to do what it must, however busy the machine is.
THREAD_GUARD_S = 30.0
ZEROS = ' '.join(['0'] * NUM_JOINTS)
HAVE_OSRF_MSGS = importlib.util.find_spec('osrf_msgs') is not None


@pytest.fixture()
def fake_master() -> Iterator[tuple[socket.socket, str]]:
    """A listening socket standing in for the ROS master; no one should connect to it."""
    server = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    server.bind(('127.0.0.1', 0))
    server.listen(8)
    server.setblocking(False)
    try:
        yield server, f'http://127.0.0.1:{server.getsockname()[1]}'
    finally:
        server.close()


def assert_untouched(server: socket.socket) -> None:
    with pytest.raises(BlockingIOError):
        connection, _ = server.accept()
        connection.close()


def run_script(args: list[str], master_uri: str, tmp_path: Path,
               first_on_path: Path | None = None) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ)
    env['PYTHONPATH'] = os.pathsep.join(filter(None, [
        str(first_on_path or ''), str(REPO / 'src'), env.get('PYTHONPATH')]))
    env['ROS_MASTER_URI'] = master_uri
    env['ROS_HOME'] = str(tmp_path / 'ros_home')
    env['ROS_LOG_DIR'] = str(tmp_path / 'ros_log')
    return subprocess.run(
        [sys.executable, str(SCRIPT), *args], env=env, cwd=tmp_path,
        capture_output=True, text=True, timeout=HANG_GUARD_S, check=False,
    )


def assert_one_line_error(result: subprocess.CompletedProcess[str], text: str) -> None:
    assert result.returncode == 1, result
    assert 'Traceback' not in result.stderr
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert text in lines[0]


def write(tmp_path: Path, text: str, name: str = 'Traj.yaml') -> Path:
    path = tmp_path / name
    path.write_text(text, encoding='utf-8')
    return path


# --- the script -------------------------------------------------------------------------


def test_script_is_thin_and_executable() -> None:
    assert os.access(SCRIPT, os.X_OK)
    text = SCRIPT.read_text(encoding='utf-8')
    assert text.startswith('#!/usr/bin/env python3\n')
    assert 'tutorial_atlas_control.cli.traj_yaml' in text
    assert len(text.splitlines()) <= 12


@pytest.mark.parametrize('args', [[], ['Traj.yaml'], ['Traj.yaml', 'step', 'extra'], ['a:=b'],
                                  ['Traj.yaml', 'x:=y']])
def test_wrong_number_of_arguments_prints_usage(args: list[str], fake_master,
                                                tmp_path: Path) -> None:
    server, uri = fake_master
    result = run_script(args, uri, tmp_path)
    assert result.returncode == 1
    assert result.stderr.splitlines() == USAGE_LINES
    assert 'Traceback' not in result.stderr
    assert_untouched(server)


@pytest.mark.parametrize('flag', ['-h', '--help'])
def test_help(flag: str, fake_master, tmp_path: Path) -> None:
    server, uri = fake_master
    result = run_script([flag], uri, tmp_path)
    assert result.returncode == 0
    assert result.stdout.splitlines()[:2] == USAGE_LINES
    assert '/atlas/joint_commands' in result.stdout and '50 Hz' in result.stdout
    assert result.stderr == ''
    assert_untouched(server)


def test_missing_file(fake_master, tmp_path: Path) -> None:
    server, uri = fake_master
    result = run_script(['absent.yaml', 'step_and_fall'], uri, tmp_path)
    assert_one_line_error(result,
                          'absent.yaml: cannot read trajectory file: No such file or directory')
    assert_untouched(server)


@pytest.mark.parametrize(
    ('text', 'expected'),
    [
        ('', 'Traj.yaml: the file is empty'),
        ('step:\n  - [1.0, "0 0"\n  - [oops\n', 'Traj.yaml: invalid YAML at line 3, column 3:'),
        ("step: !!python/object/apply:os.system ['touch pwned']\n",
         "Traj.yaml: unsupported YAML at line 1, column 7: "
         "could not determine a constructor for the tag "
         "'tag:yaml.org,2002:python/object/apply:os.system'"),
        ('- [1.0, "0"]\n',
         'Traj.yaml: expected a mapping of trajectory names to waypoints at the top level'),
        (f'step_and_fall:\n  - [1.0, "{ZEROS}"]\n  - [1.0, "{ZEROS}"]\n'
         f'  - [1.0, "{" ".join(["0"] * 27)}"]\n',
         "Traj.yaml: trajectory 'step_and_fall', waypoint 2: expected 28 joint positions, got 27"),
        (f'step_and_fall:\n  - [-1, "{ZEROS}"]\n',
         "Traj.yaml: trajectory 'step_and_fall', waypoint 0: duration must be positive, got -1 s"),
        ('step_and_fall: []\n', "Traj.yaml: trajectory 'step_and_fall': has no waypoints"),
    ],
)
def test_bad_file_is_one_line_without_ros(text: str, expected: str, fake_master,
                                          tmp_path: Path) -> None:
    server, uri = fake_master
    write(tmp_path, text)
    result = run_script(['Traj.yaml', 'step_and_fall'], uri, tmp_path)
    assert_one_line_error(result, expected)
    assert_untouched(server)
    assert not (tmp_path / 'pwned').exists()


def test_missing_trajectory_keeps_the_tutorial_message(fake_master, tmp_path: Path) -> None:
    server, uri = fake_master
    result = run_script([str(TRAJECTORY_FILE), 'nope'], uri, tmp_path)
    assert_one_line_error(result, f'unable to find trajectory nope in {TRAJECTORY_FILE}')
    assert result.stderr == (f'unable to find trajectory nope in {TRAJECTORY_FILE}; it holds: '
                             'step_and_fall, touchdown, touchdown_exhausted\n')
    assert_untouched(server)


def test_remapping_arguments_are_ignored(fake_master, tmp_path: Path) -> None:
    server, uri = fake_master
    result = run_script(['__name:=other', str(TRAJECTORY_FILE), '_joint_state_timeout:=3', 'nope'],
                        uri, tmp_path)
    assert_one_line_error(result, f'unable to find trajectory nope in {TRAJECTORY_FILE}')
    assert_untouched(server)


def free_master_uri() -> str:
    """A master URI on a port nothing listens on."""
    with socket.socket() as probe:
        probe.bind(('127.0.0.1', 0))
        return f'http://127.0.0.1:{probe.getsockname()[1]}'


@pytest.mark.skipif(not HAVE_OSRF_MSGS, reason='needs the catkin workspace: source ./env.sh')
def test_valid_file_without_master_fails_with_a_hint(tmp_path: Path) -> None:
    """Nothing listens on the master port: one line, no hang, no traceback."""
    uri = free_master_uri()
    result = run_script([str(TRAJECTORY_FILE), 'step_and_fall'], uri, tmp_path)
    assert_one_line_error(result, f'no ROS master at {uri}: start the simulator with '
                                  '`roslaunch tutorial_atlas_control atlas.launch`')


def test_without_the_workspace_the_missing_messages_are_named(tmp_path: Path) -> None:
    """osrf_msgs unimportable (a shell without the workspace, simulated by a package of that
    name that refuses to import, first on the path): one line naming what is missing."""
    shadow = tmp_path / 'shadow' / 'osrf_msgs'
    shadow.mkdir(parents=True)
    (shadow / '__init__.py').write_text(
        "raise ImportError('osrf_msgs hidden by the test')\n", encoding='utf-8')
    result = run_script([str(TRAJECTORY_FILE), 'step_and_fall'], free_master_uri(), tmp_path,
                        first_on_path=shadow.parent)
    assert_one_line_error(result, 'cannot import osrf_msgs.msg.JointCommands')


# --- joint states by name ---------------------------------------------------------------


def test_positions_by_name_reorders_and_accepts_both_spellings() -> None:
    expected = np.arange(NUM_JOINTS) * 0.1
    order = list(reversed(range(NUM_JOINTS)))
    names = [(ATLAS_PREFIX if i % 2 else '') + JOINT_NAMES[i] for i in order]
    positions = [expected[i] for i in order]
    np.testing.assert_array_equal(
        positions_by_name(names + ['hokuyo_joint'], positions + [9.0]), expected)


def test_positions_by_name_missing_joint() -> None:
    names = [name for name in JOINT_NAMES if name not in ('r_leg_kny', 'neck_ay')]
    with pytest.raises(TrajYamlError, match=r'/atlas/joint_states: the message lacks 2 Atlas '
                                            r'joint\(s\): neck_ay, r_leg_kny'):
        positions_by_name(names, [0.0] * len(names))


def test_positions_by_name_length_mismatch() -> None:
    with pytest.raises(TrajYamlError, match='28 names but 27 positions'):
        positions_by_name(list(JOINT_NAMES), [0.0] * 27)


def test_positions_by_name_duplicate() -> None:
    names = list(JOINT_NAMES) + [ATLAS_PREFIX + 'back_lbz']
    with pytest.raises(TrajYamlError, match='joint back_lbz is named twice'):
        positions_by_name(names, [0.0] * len(names))


def test_positions_by_name_not_finite() -> None:
    positions = [0.0] * NUM_JOINTS
    positions[JOINT_INDEX['l_arm_elx']] = math.nan
    with pytest.raises(TrajYamlError, match='position of l_arm_elx is nan'):
        positions_by_name(list(JOINT_NAMES), positions)


# --- waiting for the simulator ----------------------------------------------------------


def test_wait_for_joint_state_times_out_with_a_hint() -> None:
    with pytest.raises(TrajYamlError, match=r'no simulator is publishing /atlas/joint_states: '
                                            r'nothing arrived within 0\.05 s; '
                                            r'start it with `roslaunch tutorial_atlas_control'):
        wait_for_joint_state(JointStateCache(), 0.05, is_shutdown=lambda: False)


def test_wait_for_joint_state_returns_the_message() -> None:
    cache = JointStateCache()
    message = SimpleNamespace(name=list(JOINT_NAMES), position=[0.5] * NUM_JOINTS)
    cache.callback(message)
    assert wait_for_joint_state(cache, 0.05, is_shutdown=lambda: False) is message
    np.testing.assert_array_equal(cache.positions(), np.full(NUM_JOINTS, 0.5))


def test_cache_without_message() -> None:
    with pytest.raises(TrajYamlError, match='no message received on /atlas/joint_states'):
        JointStateCache().positions()


# --- gains and the command message ------------------------------------------------------


def gains_tree() -> dict[str, dict[str, float]]:
    return {name: {'p': 100.0 + i, 'i': 0.5 * i, 'd': 1.0, 'i_clamp': 2.0 * i}
            for i, name in enumerate(JOINT_NAMES)}


def test_read_gains_reads_the_tutorial_parameters() -> None:
    calls: list[tuple[object, ...]] = []

    def get_param(*args: object) -> object:
        calls.append(args)
        return gains_tree()

    gains = read_gains(get_param)
    assert calls == [('atlas_controller/gains', None)]
    assert gains.p[JOINT_INDEX['r_leg_kny']] == 113.0
    assert gains.i_clamp[JOINT_INDEX['r_arm_mwx']] == 54.0


def test_read_gains_missing_namespace() -> None:
    with pytest.raises(GainsError, match=r'parameter atlas_controller/gains is not set; .*'
                                         r'roslaunch tutorial_atlas_control atlas\.launch.*'
                                         r'rosparam load config/atlas_controller\.yaml'):
        read_gains(lambda *args: None)


def test_read_gains_missing_parameter_is_named() -> None:
    tree = gains_tree()
    del tree['l_leg_kny']['i_clamp']
    with pytest.raises(GainsError, match=r'atlas_controller/gains/l_leg_kny/i_clamp is missing;'
                                         r'.*rosparam load'):
        read_gains(lambda *args: tree)


class FakeJointCommands(SimpleNamespace):
    def __init__(self) -> None:
        super().__init__(header=SimpleNamespace(stamp=None))


def check_command(command: object, positions: np.ndarray, gains: Gains, stamp: object) -> None:
    assert command.header.stamp == stamp
    assert command.name == [f'atlas::{name}' for name in JOINT_NAMES]
    assert list(command.position) == positions.tolist()
    for field in ('velocity', 'effort', 'kp_velocity'):
        assert list(getattr(command, field)) == [0.0] * NUM_JOINTS
    assert list(command.kp_position) == gains.p.tolist()
    assert list(command.ki_position) == gains.i.tolist()
    assert list(command.kd_position) == gains.d.tolist()
    assert list(command.i_effort_max) == gains.i_clamp.tolist()
    assert list(command.i_effort_min) == (-gains.i_clamp).tolist()
    assert all(math.copysign(1.0, value) == 1.0 for value in command.i_effort_min if value == 0.0)


def test_build_command_like_the_tutorial() -> None:
    gains = read_gains(lambda *args: gains_tree())
    positions = np.linspace(-1.0, 1.0, NUM_JOINTS)
    check_command(build_command(FakeJointCommands, positions, gains, 'stamp'), positions, gains,
                  'stamp')


@pytest.mark.skipif(not HAVE_OSRF_MSGS, reason='needs the catkin workspace: source ./env.sh')
def test_build_command_serializes_as_osrf_msgs() -> None:
    from io import BytesIO

    import rospy
    from osrf_msgs.msg import JointCommands

    gains = read_gains(lambda *args: gains_tree())
    positions = np.linspace(-1.0, 1.0, NUM_JOINTS)
    stamp = rospy.Time(12, 340_000_000)
    buffer = BytesIO()
    build_command(JointCommands, positions, gains, stamp).serialize(buffer)
    received = JointCommands().deserialize(buffer.getvalue())
    check_command(received, positions, gains, stamp)


# --- the motion -------------------------------------------------------------------------


def test_run_trajectory_plays_each_waypoint_from_the_measured_pose() -> None:
    waypoints = [
        Waypoint(1.0, np.full(NUM_JOINTS, 1.0)),
        Waypoint(0.5, np.zeros(NUM_JOINTS)),
        Waypoint(0.01, np.full(NUM_JOINTS, -1.0)),
    ]
    measured = [np.full(NUM_JOINTS, 0.25), np.full(NUM_JOINTS, 0.75), np.full(NUM_JOINTS, 0.1)]
    sent: list[np.ndarray] = []
    sleeps: list[float] = []
    logs: list[str] = []
    count = run_trajectory(waypoints, lambda: measured[len(logs)], sent.append, sleeps.append,
                           logs.append)
    assert count == len(sent) == len(sleeps) == 50 + 25 + 1
    assert len(logs) == 3
    assert logs[0].startswith('waypoint 0 (1 of 3): 1 s, 50 commands; all joints move')
    np.testing.assert_array_equal(sent[0], measured[0])
    np.testing.assert_array_equal(sent[49], waypoints[0].positions)
    np.testing.assert_array_equal(sent[50], measured[1])
    np.testing.assert_array_equal(sent[74], waypoints[1].positions)
    np.testing.assert_array_equal(sent[75], waypoints[2].positions)
    assert sum(sleeps) == pytest.approx(1.51)
    assert sleeps[:50] == [pytest.approx(0.02)] * 50


class FakeClock:
    """ROS time that advances by each sleep, plus `send_s` per send (a busy machine)."""

    def __init__(self, send_s: float) -> None:
        self.t_s = 100.0
        self.send_s = send_s
        self.send_times: list[float] = []

    def send(self, _positions: np.ndarray) -> None:
        self.send_times.append(self.t_s)
        self.t_s += self.send_s

    def sleep(self, duration_s: float) -> None:
        assert duration_s > 0.0
        self.t_s += duration_s


@pytest.mark.parametrize('send_s', [0.0, 0.004, 0.019])
def test_commands_keep_50_hz_and_the_durations_when_sends_are_late(send_s: float) -> None:
    waypoints = [Waypoint(1.0, np.ones(NUM_JOINTS)), Waypoint(2.0, np.zeros(NUM_JOINTS))]
    clock = FakeClock(send_s)
    count = run_trajectory(waypoints, lambda: np.zeros(NUM_JOINTS), clock.send, clock.sleep,
                           lambda _: None, lambda: clock.t_s)
    assert count == 150
    periods = np.diff(clock.send_times)
    np.testing.assert_allclose(periods, 0.02, atol=1e-9)
    # The second waypoint starts exactly 1 s after the first (the tutorial: 1 s + 50 x send_s).
    assert clock.send_times[50] - clock.send_times[0] == pytest.approx(1.0)


def test_a_stall_restarts_the_schedule_instead_of_a_burst() -> None:
    clock = FakeClock(0.0)
    stalled = []

    def send(positions: np.ndarray) -> None:
        clock.send(positions)
        if len(clock.send_times) == 10:
            clock.t_s += 0.5  # the process was not scheduled for 0.5 s
            stalled.append(clock.t_s)

    run_trajectory([Waypoint(1.0, np.ones(NUM_JOINTS))], lambda: np.zeros(NUM_JOINTS), send,
                   clock.sleep, lambda _: None, lambda: clock.t_s)
    periods = np.diff(clock.send_times)
    assert periods.min() > 0.0, 'no two commands at the same time (a burst)'
    np.testing.assert_allclose(periods[10:], 0.02, atol=1e-9)


def test_sim_time_going_back_between_sends_aborts_with_one_line() -> None:
    """/gazebo/reset_simulation while playing (a jump within a sleep: traj_yaml's _sleep)."""
    clock = FakeClock(0.0)
    clock.t_s = 12.0

    def send(positions: np.ndarray) -> None:
        clock.send(positions)
        if len(clock.send_times) == 10:
            clock.t_s = 0.05  # reset_simulation: sim time back to 0

    with pytest.raises(TimeWentBackError) as raised:
        run_trajectory([Waypoint(1.0, np.ones(NUM_JOINTS))], lambda: np.zeros(NUM_JOINTS),
                       send, clock.sleep, lambda _: None, lambda: clock.t_s)
    assert str(raised.value) == (
        'sim time went back from 12.160 s to 0.050 s (the simulation was reset: '
        '/gazebo/reset_simulation?); trajectory aborted, run traj_yaml.py again to play it '
        'from the start')
    assert len(clock.send_times) == 10, 'nothing sent after the jump'


def test_waypoint_log_names_the_moving_joints() -> None:
    target = np.zeros(NUM_JOINTS)
    target[JOINT_INDEX['r_leg_kny']] = 1.4
    target[JOINT_INDEX['neck_ay']] = 0.005  # under the threshold
    logs: list[str] = []
    run_trajectory([Waypoint(0.1, target)], lambda: np.zeros(NUM_JOINTS), lambda _: None,
                   lambda _: None, logs.append)
    assert logs == [f'waypoint 0 (1 of 1): 0.1 s, {sample_count(0.1)} commands; moving r_leg_kny']


class BlockingTransport:
    """A subscriber connection whose writes block until `release` is set (a slow socket)."""

    def __init__(self, hold_s: float = 5.0) -> None:
        self.done = False
        self.release = threading.Event()
        self.hold_s = hold_s  # the longest a write blocks without `release`
        self.written: list[bytes] = []

    def set_cleanup_callback(self, _callback: object) -> None:
        pass

    def write_data(self, data: bytes) -> bool:
        self.release.wait(self.hold_s)
        self.written.append(data)
        return True


def test_the_port_waits_until_rospy_has_taken_each_command() -> None:
    """rospy's own queue_size=1 connection: a command still queued is reported, not lost."""
    from rospy.impl.tcpros_pubsub import QueuedConnection

    transport = BlockingTransport()
    connection = QueuedConnection(transport, 1)
    publisher = SimpleNamespace(impl=SimpleNamespace(connections=[connection]))
    try:
        connection.write_data(b'first')
        assert wait_until_handed_over(publisher, THREAD_GUARD_S), \
            'the writer thread takes the first command'
        connection.write_data(b'second')  # the writer is still busy with 'first'
        started = time.monotonic()
        assert not wait_until_handed_over(publisher, 0.05)
        assert time.monotonic() - started >= 0.05
        transport.release.set()
        assert wait_until_handed_over(publisher, THREAD_GUARD_S)
        deadline = time.monotonic() + THREAD_GUARD_S
        while len(transport.written) < 2 and time.monotonic() < deadline:
            time.sleep(0.001)
        assert transport.written == [b'first', b'second']
    finally:
        transport.release.set()
        transport.done = True
        with connection._lock:
            connection._cond_data_available.notify()


def wait_until_drained(connection: object) -> None:
    """Until the writer thread of rospy's `connection` has taken its queued message."""
    deadline = time.monotonic() + THREAD_GUARD_S
    while connection._queue and time.monotonic() < deadline:  # type: ignore[attr-defined]
        time.sleep(0.001)


def test_a_stalled_subscriber_delays_the_port_once_and_the_others_are_still_waited_for() -> None:
    """A connection still queued at a wait's end is skipped by the next waits (a subscriber
    that stopped reading), until its queue empties; the others are waited for throughout."""
    from rospy.impl.tcpros_pubsub import QueuedConnection

    stuck, slow = BlockingTransport(hold_s=THREAD_GUARD_S), BlockingTransport()
    connections = [QueuedConnection(stuck, 1), QueuedConnection(slow, 1)]
    publisher = SimpleNamespace(impl=SimpleNamespace(connections=connections))
    stalled: set[int] = set()
    try:
        for connection in connections:
            connection.write_data(b'first')  # each writer thread takes it, then blocks
        assert wait_until_handed_over(publisher, THREAD_GUARD_S, stalled)
        for connection in connections:
            connection.write_data(b'second')  # queued behind the blocked writes
        assert not wait_until_handed_over(publisher, 0.05, stalled)
        assert stalled == {id(connection) for connection in connections}
        slow.release.set()  # the slow one catches up; the stuck one never does
        wait_until_drained(connections[1])
        assert wait_until_handed_over(publisher, THREAD_GUARD_S, stalled)
        assert stalled == {id(connections[0])}
        slow.release.clear()
        connections[1].write_data(b'third')  # taken, and its write blocks
        assert wait_until_handed_over(publisher, THREAD_GUARD_S, stalled)
        connections[1].write_data(b'fourth')  # the slow one is waited for again
        assert not wait_until_handed_over(publisher, 0.05, stalled)
        assert stalled == {id(connection) for connection in connections}
        slow.release.set()
        wait_until_drained(connections[1])
        assert wait_until_handed_over(publisher, THREAD_GUARD_S, stalled)
        assert stalled == {id(connections[0])}
        connections[0].write_data(b'third')  # replaces 'second' in the stuck queue
        # waited for, the stuck queue would make this wait time out (False)
        assert wait_until_handed_over(publisher, 0.05, stalled), 'the stuck one was waited for'
    finally:
        for transport, connection in zip((stuck, slow), connections, strict=True):
            transport.release.set()
            transport.done = True
            with connection._lock:
                connection._cond_data_available.notify()


def test_handover_wait_without_connections_returns_at_once() -> None:
    assert wait_until_handed_over(SimpleNamespace(impl=None), 1.0)
    assert wait_until_handed_over(SimpleNamespace(impl=SimpleNamespace(connections=[])), 1.0)


# --- waiting for the subscribers ------------------------------------------------------------

SIM, RECORDER = '/atlas_sim', '/atlas_recorder'


class Connecting:
    """connected() for wait_for_subscribers: each node connects after its number of polls."""

    def __init__(self, polls_until_connected: dict[str, int]) -> None:
        self.polls_until_connected = polls_until_connected
        self.polls = 0

    def __call__(self) -> set[str]:
        self.polls += 1
        return {node for node, polls in self.polls_until_connected.items() if self.polls > polls}


def never_shut_down() -> bool:
    return False


def test_subscribers_all_connected_return_at_once() -> None:
    connected = Connecting({SIM: 0, RECORDER: 0})
    assert wait_for_subscribers(connected, lambda: {SIM, RECORDER}, SIM, 5.0,
                                never_shut_down) == set()
    assert connected.polls == 1


def test_a_simulator_that_connects_late_is_waited_for() -> None:
    """The CI failure: the simulator connected after the old 2 s and missed the first commands."""
    connected = Connecting({RECORDER: 0, SIM: 30})  # 30 polls of 10 ms
    started = time.monotonic()
    assert wait_for_subscribers(connected, lambda: {SIM, RECORDER}, SIM, 5.0,
                                never_shut_down) == set()
    assert connected.polls == 31
    assert time.monotonic() - started >= 0.25


def test_a_simulator_that_never_connects_is_an_error_naming_it() -> None:
    connected = Connecting({RECORDER: 0})
    with pytest.raises(TrajYamlError) as err:
        wait_for_subscribers(connected, lambda: {SIM, RECORDER}, SIM, 0.2, never_shut_down)
    assert (f'the simulator {SIM} subscribes to /atlas/joint_commands '
            'but did not connect within 0.2 s') in str(err.value)
    assert '~subscriber_timeout' in str(err.value)


def test_no_subscriber_at_all_is_an_error() -> None:
    with pytest.raises(TrajYamlError, match='nothing subscribed to /atlas/joint_commands '
                                            'within 0.2 s.*atlas.launch'):
        wait_for_subscribers(Connecting({}), set, SIM, 0.2, never_shut_down)


def test_another_late_subscriber_is_returned_for_a_warning() -> None:
    missing = wait_for_subscribers(Connecting({SIM: 0}), lambda: {SIM, RECORDER}, SIM, 0.2,
                                   never_shut_down)
    assert missing == {RECORDER}


def test_a_master_that_cannot_tell_keeps_the_last_list() -> None:
    """None from the master is no answer: the recorder it listed before is still waited for."""
    answers = iter([{SIM, RECORDER}] + [None] * 1000)
    connected = Connecting({SIM: 0, RECORDER: 15})
    assert wait_for_subscribers(connected, lambda: next(answers), SIM, 5.0,
                                never_shut_down) == set()
    assert connected.polls == 16


def test_shutdown_while_waiting_for_subscribers() -> None:
    import rospy

    with pytest.raises(rospy.ROSInterruptException):
        wait_for_subscribers(Connecting({}), lambda: {SIM}, SIM, 5.0, lambda: True)


# --- waiting for ROS time -------------------------------------------------------------------

def test_ros_time_is_awaited_until_the_first_clock() -> None:
    """Sim time is 0 until /clock arrives; the first command must not be stamped 0."""
    readings = iter([0.0] * 5 + [3.25])
    assert wait_for_ros_time(5.0, lambda: next(readings), never_shut_down) == 3.25


def test_no_clock_is_an_error() -> None:
    with pytest.raises(TrajYamlError,
                       match='/use_sim_time is set but no /clock arrived within 0.1 s'):
        wait_for_ros_time(0.1, lambda: 0.0, never_shut_down)


def test_bare_name_is_taken_from_the_package_trajectories_folder(fake_master,
                                                                 tmp_path: Path) -> None:
    """The tutorial's `traj_yaml.py Traj_data2.yaml ...` from anywhere: one line names the file."""
    server, uri = fake_master
    result = run_script(['Traj_data2.yaml', 'no_such_trajectory'], uri, tmp_path)
    assert result.stdout.splitlines() == [
        f'Traj_data2.yaml is not in the current directory; using {TRAJECTORY_FILE}']
    assert_one_line_error(result,
                          f'unable to find trajectory no_such_trajectory in {TRAJECTORY_FILE}')
    assert_untouched(server)


def test_explicit_missing_path_is_not_redirected(fake_master, tmp_path: Path) -> None:
    server, uri = fake_master
    result = run_script(['./Traj_data2.yaml', 'step_and_fall'], uri, tmp_path)
    assert result.stdout == ''
    assert_one_line_error(
        result, './Traj_data2.yaml: cannot read trajectory file: No such file or directory')
    assert_untouched(server)


@pytest.mark.parametrize('mode', ['Stand', 'StandPrep', 'Freeze', 'ragdoll'])
def test_a_mode_other_than_user_is_warned_about_with_the_command_to_send(mode: str) -> None:
    assert mode_warning(mode) == (
        f'the simulator is in {mode} mode, which does not apply these commands: the robot will '
        'not move; switch to User mode first: '
        'rostopic pub /atlas/control_mode std_msgs/String -- "User"')


@pytest.mark.parametrize('mode', ['User', None])  # None: a simulator that does not say
def test_user_mode_or_an_unknown_one_gives_no_warning(mode: str | None) -> None:
    assert mode_warning(mode) is None


@pytest.mark.parametrize('shut_down, expected', [(True, 130), (False, None)])
def test_a_publish_racing_the_ctrl_c_shutdown_is_an_interrupt(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path, shut_down: bool,
        expected: int | None) -> None:
    """Seen beside a busy core: rospy's shutdown thread closed the publisher between the
    node's check and its publish(), and the port died with a traceback and exit 1."""
    import rospy

    from tutorial_atlas_control.cli import traj_yaml as cli

    class SeenSigint:
        seen = True

        def install(self) -> None: ...

        def wait(self, _timeout_s: float) -> None: ...

    def play(*_args: object) -> None:
        raise rospy.ROSException('publish() to a closed topic')

    monkeypatch.setattr(cli, 'locate_trajectory_file', lambda path, announce: path)
    monkeypatch.setattr(cli, 'load_trajectory', lambda path, name: [])
    monkeypatch.setattr(cli, 'joint_commands_type', lambda: object)
    monkeypatch.setattr(cli, 'require_master', lambda: None)
    monkeypatch.setattr(cli.rospy, 'init_node', lambda *args, **kwargs: None)
    monkeypatch.setattr(cli.rospy.core, 'is_shutdown_requested', lambda: shut_down)
    monkeypatch.setattr(cli.rospy, 'logwarn', lambda _text: None)
    monkeypatch.setattr(cli, '_SigintSeen', SeenSigint)
    monkeypatch.setattr(cli, 'play', play)
    if expected is None:  # not a shutdown: a real error, not hidden
        with pytest.raises(rospy.ROSException):
            cli.main([str(tmp_path / 'x.yaml'), 'step_and_fall'])
    else:
        assert cli.main([str(tmp_path / 'x.yaml'), 'step_and_fall']) == expected


# --- waiting for the readers of /rosout -----------------------------------------------------

ROSOUT_NODE = '/rosout'


def test_a_recorder_that_reads_rosout_late_is_waited_for() -> None:
    """The trajectory line goes out only once the recorder reads /rosout: latched one deep,
    it would otherwise be replaced by the next line before the recorder connects."""
    connected = Connecting({ROSOUT_NODE: 0, RECORDER: 20})
    assert wait_for_log_readers(connected, lambda: {ROSOUT_NODE, RECORDER}, 5.0,
                                never_shut_down) == set()
    assert connected.polls == 21


def test_a_reader_that_never_connects_is_returned_after_the_timeout() -> None:
    started = time.monotonic()
    missing = wait_for_log_readers(Connecting({ROSOUT_NODE: 0}),
                                   lambda: {ROSOUT_NODE, RECORDER}, 0.2, never_shut_down)
    assert missing == {RECORDER}
    assert time.monotonic() - started >= 0.2


def test_no_reader_of_rosout_needs_no_wait() -> None:
    connected = Connecting({})
    assert wait_for_log_readers(connected, set, 5.0, never_shut_down) == set()
    assert connected.polls == 1


def test_a_shutdown_ends_the_wait_for_rosout_readers() -> None:
    import rospy

    with pytest.raises(rospy.ROSInterruptException):
        wait_for_log_readers(Connecting({}), lambda: {RECORDER}, 5.0, lambda: True)


# --- staying up after the last command ------------------------------------------------------


def test_the_port_stays_up_its_grace_after_the_last_command() -> None:
    """Slow subscribers read the tail before rospy's shutdown makes roscpp drop them."""
    started = time.monotonic()
    linger(0.2, never_shut_down)
    assert time.monotonic() - started >= 0.2


def test_ctrl_c_cuts_the_grace_short() -> None:
    asked = []

    def shut_down_at_the_third_look() -> bool:
        asked.append(True)
        return len(asked) >= 3

    linger(30.0, shut_down_at_the_third_look)
    assert len(asked) == 3
